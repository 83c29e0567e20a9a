#include "scene/vdb_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>

#include "base/error.hpp"
#include "base/file_access.hpp"

#ifdef CANDELA_HAVE_NANOVDB
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>
#endif
#ifdef CANDELA_HAVE_OPENVDB
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>
#endif

namespace candela {

#ifdef CANDELA_HAVE_NANOVDB

namespace {

// Majorant cells per axis of a NanoVDB grid's box (fewer where it spans fewer voxels)
constexpr int kMajorantCells = 16;

// The majorant cells of a grid: cell c spans [lo + c w, lo + (c + 1) w] in index space. A
// trilinear lookup at index point q reads voxels floor(q) and floor(q) + 1 on each axis, so
// voxel i is read from cells that reach into [i - 1, i + 1).
struct MajorantCells {
  glm::dvec3 lo{0.0}, width{1.0};
  glm::ivec3 n{0};
  std::vector<float> peak;  // x fastest

  // Every voxel of [a, b] holds v: raise the cells whose lookups can read one of them
  void add(const nanovdb::Coord& a, const nanovdb::Coord& b, float v, const std::string& what) {
    if (!std::isfinite(v)) throw Error(what + " holds a value that is not finite");
    int c0[3], c1[3];
    for (int k = 0; k < 3; ++k) {
      // cell c reads voxel i when lo + c w < i + 1 and lo + (c + 1) w >= i - 1
      double first = std::ceil((double(a[k]) - 1.0 - lo[k]) / width[k]) - 1.0;
      double last = std::ceil((double(b[k]) + 1.0 - lo[k]) / width[k]) - 1.0;
      c0[k] = int(std::max(first, 0.0));
      c1[k] = int(std::min(last, double(n[k] - 1)));
      if (c0[k] > c1[k]) return;
    }
    for (int z = c0[2]; z <= c1[2]; ++z)
      for (int y = c0[1]; y <= c1[1]; ++y)
        for (int x = c0[0]; x <= c1[0]; ++x) {
          float& p = peak[(size_t(z) * n.y + y) * n.x + x];
          p = std::max(p, v);
        }
  }
};

// The grid of `handle` into m: its buffer, its index-space box (the active voxels and one
// voxel around them, beyond which the density is 0) and its majorant cells, bounds of every
// value the lookups in each cell can read: root tiles, internal-node tiles and every voxel of
// every leaf, active or not, and the background where none of them is
void set_nanovdb_grid(const nanovdb::GridHandle<nanovdb::HostBuffer>& handle, const std::string& what, MediumDesc* m) {
  const nanovdb::FloatGrid* grid = handle.grid<float>();
  if (!grid) throw Error(what + " is not a float grid");
  const nanovdb::CoordBBox box = grid->indexBBox();
  if (box.empty()) throw Error(what + " has no active voxels");
  uint64_t bytes = grid->gridSize();
  if (bytes >= (uint64_t(1) << 32)) throw Error(what + " is larger than 4 GiB, more than candela's kernel addresses");
  m->nanovdb.assign(size_t((bytes + 3) / 4), 0u);
  std::memcpy(m->nanovdb.data(), grid, size_t(bytes));
  m->grid_source = what;

  MajorantCells cells;
  for (int k = 0; k < 3; ++k) {
    m->grid_min[k] = float(box.min()[k] - 1);
    m->grid_max[k] = float(box.max()[k] + 1);
    double extent = double(m->grid_max[k]) - double(m->grid_min[k]);
    cells.n[k] = int(std::min<double>(kMajorantCells, extent));
    cells.lo[k] = m->grid_min[k];
    cells.width[k] = extent / cells.n[k];
  }
  const auto& tree = grid->tree();
  const auto& root = tree.root();
  cells.peak.assign(size_t(cells.n.x) * cells.n.y * cells.n.z, std::max(root.background(), 0.0f));
  using Upper = nanovdb::NanoUpper<float>;
  using Lower = nanovdb::NanoLower<float>;
  using Leaf = nanovdb::NanoLeaf<float>;
  auto span = [](const nanovdb::Coord& o, uint32_t dim) { return o + nanovdb::Coord(int(dim) - 1); };
  for (uint32_t i = 0; i < root.tileCount(); ++i) {
    const auto* tile = root.data()->tile(i);
    if (tile->isValue()) cells.add(tile->origin(), span(tile->origin(), Upper::DIM), tile->value, what);
  }
  const Upper* uppers = tree.getFirstUpper();
  for (uint32_t u = 0; u < tree.nodeCount(2); ++u)
    for (uint32_t n = 0; n < Upper::SIZE; ++n)
      if (!uppers[u].data()->isChild(n)) {
        nanovdb::Coord o = uppers[u].offsetToGlobalCoord(n);
        cells.add(o, span(o, Lower::DIM), uppers[u].data()->getValue(n), what);
      }
  const Lower* lowers = tree.getFirstLower();
  for (uint32_t l = 0; l < tree.nodeCount(1); ++l)
    for (uint32_t n = 0; n < Lower::SIZE; ++n)
      if (!lowers[l].data()->isChild(n)) {
        nanovdb::Coord o = lowers[l].offsetToGlobalCoord(n);
        cells.add(o, span(o, Leaf::DIM), lowers[l].data()->getValue(n), what);
      }
  const Leaf* leaves = tree.getFirstLeaf();
  for (uint32_t l = 0; l < tree.nodeCount(0); ++l)
    for (uint32_t n = 0; n < Leaf::SIZE; ++n) {
      float v = leaves[l].getValue(n);
      if (v > 0.0f || !std::isfinite(v)) {
        nanovdb::Coord o = leaves[l].offsetToGlobalCoord(n);
        cells.add(o, o, v, what);
      }
    }
  m->majorant_size = cells.n;
  m->majorant_density = std::move(cells.peak);
}

}  // namespace

bool nanovdb_supported() { return true; }

void load_nanovdb_density(const std::string& path, const std::string& grid_name, MediumDesc* m) {
  check_regular_file(path, "NanoVDB file");
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  try {
    handle = grid_name.empty() ? nanovdb::io::readGrid(path) : nanovdb::io::readGrid(path, grid_name);
  } catch (const std::exception& e) {
    throw Error("cannot read NanoVDB file " + path + ": " + e.what());
  }
  if (!handle) throw Error("NanoVDB file " + path + ": no grid" + (grid_name.empty() ? "" : " named " + grid_name));
  set_nanovdb_grid(handle, "NanoVDB grid " + (grid_name.empty() ? std::string("#0") : grid_name) + " of " + path, m);
}

#else

bool nanovdb_supported() { return false; }

void load_nanovdb_density(const std::string& path, const std::string&, MediumDesc*) {
  throw Error("cannot read NanoVDB file " + path + ": candela was built without NanoVDB (libnanovdb-dev)");
}

#endif

#ifdef CANDELA_HAVE_OPENVDB

bool openvdb_supported() { return true; }

void load_openvdb_density(const std::string& path, const std::string& grid_name, MediumDesc* m) {
  check_regular_file(path, "OpenVDB file");
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  openvdb::FloatGrid::Ptr grid;
  std::string name = grid_name;
  try {
    openvdb::io::File file(path);
    file.open();
    if (name.empty()) {  // the first float grid
      for (auto it = file.beginName(); it != file.endName() && !grid; ++it) {
        grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(it.gridName()));
        if (grid) name = it.gridName();
      }
      if (!grid) throw Error("OpenVDB file " + path + " holds no float grid");
    } else {
      if (!file.hasGrid(name)) throw Error("OpenVDB file " + path + " has no grid named " + name);
      grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(name));
      if (!grid) throw Error("OpenVDB grid " + name + " of " + path + " is not a float grid");
    }
    file.close();
  } catch (const openvdb::Exception& e) {
    throw Error("cannot read OpenVDB file " + path + ": " + e.what());
  }
  if (!grid->transform().isLinear())
    throw Error("OpenVDB grid " + name + " of " + path +
                " has a frustum (non-linear) transform; candela reads affine ones");
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  try {
    handle = nanovdb::openToNanoVDB(*grid);
  } catch (const std::exception& e) {
    throw Error("cannot convert OpenVDB grid " + name + " of " + path + " to NanoVDB: " + e.what());
  }
  set_nanovdb_grid(handle, "OpenVDB grid " + name + " of " + path, m);
}

#else

bool openvdb_supported() { return false; }

void load_openvdb_density(const std::string& path, const std::string&, MediumDesc*) {
  throw Error("cannot read OpenVDB file " + path + ": candela was built without OpenVDB (libopenvdb-dev)");
}

#endif

}  // namespace candela
