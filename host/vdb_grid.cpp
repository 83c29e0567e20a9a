#include "vdb_grid.hpp"

#include <cmath>

#include "error.hpp"

#ifdef CANDELA_HAVE_NANOVDB
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>
#endif

namespace candela {

// Dense grids past this many values (256 MiB of floats) are refused
constexpr size_t kMaxDenseValues = size_t(1) << 26;

#ifdef CANDELA_HAVE_NANOVDB

bool nanovdb_supported() { return true; }

void load_nanovdb_density(const std::string& path, const std::string& grid_name, MediumDesc* m) {
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  try {
    handle = grid_name.empty() ? nanovdb::io::readGrid(path) : nanovdb::io::readGrid(path, grid_name);
  } catch (const std::exception& e) {
    throw Error("cannot read NanoVDB file " + path + ": " + e.what());
  }
  const nanovdb::FloatGrid* grid = handle.grid<float>();
  if (!grid) throw Error("NanoVDB file " + path + ": no float grid" + (grid_name.empty() ? "" : " named " + grid_name));
  const nanovdb::CoordBBox box = grid->indexBBox();
  if (box.empty()) throw Error("NanoVDB grid in " + path + " has no active voxels");
  // One node of background around the active box, so the density fades to it over a voxel
  nanovdb::Coord lo = box.min() - nanovdb::Coord(1), hi = box.max() + nanovdb::Coord(1);
  size_t count = 1;
  for (int k = 0; k < 3; ++k) {
    m->grid_size[k] = hi[k] - lo[k] + 1;
    count *= size_t(m->grid_size[k]);
  }
  if (count > kMaxDenseValues)
    throw Error("NanoVDB grid in " + path + " spans " + std::to_string(count) + " voxels, more than candela's dense grids hold (2^26)");
  // Scale and translation only: index axes map onto world axes
  nanovdb::Vec3d o = grid->indexToWorld(nanovdb::Vec3d(0.0));
  for (int k = 0; k < 3; ++k) {
    nanovdb::Vec3d e(0.0);
    e[k] = 1.0;
    nanovdb::Vec3d d = grid->indexToWorld(e) - o;
    for (int j = 0; j < 3; ++j)
      if (j != k && std::fabs(d[j]) > 1e-9 * std::fabs(d[k]))
        throw Error("NanoVDB grid in " + path + " is rotated or sheared; candela reads axis-aligned grids only");
    if (!(d[k] > 0.0)) throw Error("NanoVDB grid in " + path + " has a mirrored or degenerate voxel size");
  }
  nanovdb::Vec3d wlo = grid->indexToWorld(lo.asVec3d()), whi = grid->indexToWorld(hi.asVec3d());
  for (int k = 0; k < 3; ++k) {
    m->grid_min[k] = float(wlo[k]);
    m->grid_max[k] = float(whi[k]);
  }
  auto acc = grid->getAccessor();
  m->density.resize(count);
  size_t i = 0;
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x) {
        float v = acc.getValue(nanovdb::Coord(x, y, z));
        if (!(v >= 0.0f) || !std::isfinite(v)) v = 0.0f;  // densities are non-negative
        m->density[i++] = v;
      }
}

#else

bool nanovdb_supported() { return false; }

void load_nanovdb_density(const std::string& path, const std::string&, MediumDesc*) {
  throw Error("cannot read NanoVDB file " + path + ": candela was built without NanoVDB (libnanovdb-dev)");
}

#endif

}  // namespace candela
