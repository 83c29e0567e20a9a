#include "compile/scene_compiler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "base/error.hpp"
#include "compile/bvh_builder.hpp"
#include "compile/environment_distribution.hpp"
#include "compile/light_tree.hpp"
#include "scene/environment.hpp"

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Device arithmetic is single precision and squares distances: coordinates beyond this
// (far past any real scene) overflow it, and the image would be silently wrong
constexpr float kMaxCoordinate = 1e15f;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

template <int N, typename V>
void append(std::vector<float>* out, const V& v) {
  for (int i = 0; i < N; ++i) out->push_back(v[i]);
}

// Appends `values` (N floats each) for a mesh of n vertices, or `fallback` for each
// vertex when the mesh lacks the attribute
template <int N, typename V>
void append_attribute(std::vector<float>* out, const std::vector<V>& values, size_t n, const V& fallback) {
  for (size_t i = 0; i < n; ++i) append<N>(out, values.empty() ? fallback : values[i]);
}

// Vertices and primitives of every mesh, in mesh order: stable primitive indices.
// Optional arrays are filled only when the scene's features read them.
void compile_geometry(const Scene& scene, const SceneFeatures& f, dev::SceneBuffers* b) {
  for (const MeshDesc& m : scene.meshes) {
    size_t n = m.positions.size(), base = b->positions.size() / 3;
    if (base + n > size_t(UINT32_MAX)) throw Error("the scene has more than 2^32 vertices");
    append_attribute<3>(&b->positions, m.positions, n, glm::vec3(0.0f));
    append_attribute<3>(&b->normals, m.normals, n, glm::vec3(0.0f));
    if (f.uvs) {
      append_attribute<2>(&b->uv0, m.uv0, n, glm::vec2(0.0f));
      append_attribute<2>(&b->uv1, m.uv1, n, glm::vec2(0.0f));
    }
    if (f.tangents) append_attribute<4>(&b->tangents, m.tangents, n, glm::vec4(0.0f));
    if (f.vertex_colors) append_attribute<3>(&b->colors, m.colors, n, glm::vec3(1.0f));
    for (size_t t = 0; t < m.triangles(); ++t) {
      dev::Prim p{};
      for (int k = 0; k < 3; ++k) p.v[k] = uint32_t(base + m.indices[3 * t + k]);
      p.material = m.material;
      b->prims.push_back(p);
    }
  }
}

// Motion blur: positions and normals replaced by every mesh's poses across the shutter
// (MeshDesc::motion_positions), in the same vertex order; what was compiled before from the
// middle pose (lights) keeps it
void compile_motion(const Scene& scene, dev::SceneBuffers* b) {
  const size_t poses = size_t(scene.motion_steps) + 1;
  std::vector<float> positions, normals;
  positions.reserve(b->positions.size() * poses);
  normals.reserve(b->positions.size() * poses);
  for (const MeshDesc& m : scene.meshes) {
    size_t n = m.positions.size() * poses;
    if (m.motion_positions.size() != n) throw Error("compile_scene: a mesh lacks its motion poses");
    append_attribute<3>(&positions, m.motion_positions, n, glm::vec3(0.0f));
    append_attribute<3>(&normals, m.motion_normals.size() == n ? m.motion_normals : std::vector<glm::vec3>(), n,
                        glm::vec3(0.0f));
  }
  b->positions = std::move(positions);
  b->normals = std::move(normals);
}

dev::TextureRef compile_texture_ref(const TextureSlot& r) {
  dev::TextureRef d{};
  d.index = r.index;
  d.texcoord = uint32_t(r.texcoord);
  // Rows of the affine 2D part of the column-major 3x3 transform
  const glm::mat3& m = r.transform;
  float rows[6] = {m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1]};
  std::copy(rows, rows + 6, d.m);
  return d;
}

// The parameters of each material type (CD_MATERIALS), into Material.params
void compile_material_diffuse(const MaterialDesc&, dev::Material*) {}

// GLTF_PARAMS, each factor as the loader read it
void copy_factor(float& to, float v) { to = v; }
void copy_factor(float (&to)[3], const glm::vec3& v) {
  for (int c = 0; c < 3; ++c) to[c] = v[c];
}

void compile_material_gltf(const MaterialDesc& m, dev::Material* d) {
  dev::GltfMaterial& g = d->params.gltf;
#define CD_COPY_PARAM(_, name, ...) copy_factor(g.name, m.name);
  GLTF_PARAMS(CD_COPY_PARAM)
#undef CD_COPY_PARAM
}

void compile_material_conductor(const MaterialDesc& m, dev::Material* d) {
  dev::ConductorMaterial& c = d->params.conductor;
  for (int k = 0; k < 3; ++k) {
    c.eta[k] = m.conductor_eta[k];
    c.k[k] = m.conductor_k[k];
  }
  c.roughness = m.roughness;
  c.anisotropy_strength = m.anisotropy_strength;
  c.anisotropy_rotation = m.anisotropy_rotation;
}

void compile_materials(const Scene& scene, dev::SceneBuffers* b) {
  for (const MaterialDesc& m : scene.materials) {
    dev::Material d{};
    d.type = m.kernel_type();
    if (!dev::material_type_name(d.type)) throw Error("compile_scene: unknown material type " + std::to_string(d.type));
    d.flags = (m.double_sided ? MATERIAL_DOUBLE_SIDED : 0u) | (m.thin_walled ? MATERIAL_THIN_WALLED : 0u) |
              (m.alpha_mode == AlphaMode::Mask ? MATERIAL_ALPHA_MASK : 0u) |
              (m.alpha_mode == AlphaMode::Blend ? MATERIAL_ALPHA_BLEND : 0u);
    d.flags |= m.null_boundary ? MATERIAL_NULL_BOUNDARY : 0u;
    d.flags |= m.unlit ? MATERIAL_UNLIT : 0u;
    d.medium = NO_MEDIUM;  // compile_media sets the insides of closed surfaces
    d.alpha_cutoff = m.alpha_cutoff;
    d.normal_scale = m.normal_scale;
    for (int c = 0; c < 4; ++c) d.base_color[c] = m.base_color[c];
    for (int c = 0; c < 3; ++c) d.emission[c] = m.emission[c];
    for (int slot = 0; slot < TEX_SLOTS; ++slot) d.textures[slot] = compile_texture_ref(m.textures[slot]);
#define CD_COMPILE_MATERIAL(id, name, feature) \
  if (d.type == id) compile_material_##name(m, &d);
    CD_MATERIALS(CD_COMPILE_MATERIAL)
#undef CD_COMPILE_MATERIAL
    b->materials.push_back(d);
  }
}

void compile_textures(const Scene& scene, dev::SceneBuffers* b) {
  for (const TextureDesc& t : scene.textures) {
    dev::TextureInfo info{};
    bool is_float = !t.rgbaf.empty();
    size_t offset = is_float ? b->texelsf.size() : b->texels8.size();
    if (offset + t.texels() > size_t(UINT32_MAX)) throw Error("the scene's textures hold more than 2^32 texels");
    info.offset = uint32_t(offset);
    info.width = uint32_t(t.width);
    info.height = uint32_t(t.height);
    info.flags = t.wrap_s | (t.wrap_t << 8) | (t.srgb ? TEXTURE_SRGB : 0u) | (is_float ? TEXTURE_FLOAT : 0u) |
                 (t.nearest ? TEXTURE_NEAREST : 0u);
    for (size_t i = 0; i < t.texels(); ++i) {
      if (is_float)
        b->texelsf.push_back({{t.rgbaf[4 * i], t.rgbaf[4 * i + 1], t.rgbaf[4 * i + 2], t.rgbaf[4 * i + 3]}});
      else
        b->texels8.push_back({t.rgba8[4 * i], t.rgba8[4 * i + 1], t.rgba8[4 * i + 2], t.rgba8[4 * i + 3]});
    }
    b->textures.push_back(info);
  }
  for (int i = 0; i < 256; ++i) b->srgb_to_linear.push_back(dev::srgb_to_linear(i / 255.0f));
}

// Majorant cells per axis of a density grid (fewer where the grid has fewer cells)
constexpr int kMajorantCells = 16;

// A NanoVDB grid (MEDIUM_NANOVDB): its buffer goes to `nanovdb` on a 32-byte boundary (8
// words), and its majorant cells, scaled to bounds of sigma_t, to `densities`
void compile_nanovdb_grid(const MediumDesc& m, float scale, dev::Medium* d, dev::SceneBuffers* b) {
  d->type = MEDIUM_NANOVDB;
  b->nanovdb.resize((b->nanovdb.size() + 7) / 8 * 8, 0u);
  if (b->nanovdb.size() + m.nanovdb.size() > size_t(UINT32_MAX))
    throw Error("the scene's NanoVDB grids hold more than 16 GiB");
  d->grid_offset = uint32_t(b->nanovdb.size());
  b->nanovdb.insert(b->nanovdb.end(), m.nanovdb.begin(), m.nanovdb.end());
  float peak = *std::max_element(m.majorant_density.begin(), m.majorant_density.end());
  d->majorant = scale * peak;
  for (int k = 0; k < 3; ++k) {
    d->grid_min[k] = m.grid_min[k];
    d->grid_max[k] = m.grid_max[k];
    d->majorant_size[k] = uint32_t(m.majorant_size[k]);
  }
  if (b->densities.size() + m.majorant_density.size() > size_t(UINT32_MAX))
    throw Error("the scene's density grids hold more than 2^32 values");
  d->majorant_offset = uint32_t(b->densities.size());
  for (float v : m.majorant_density) b->densities.push_back(scale * v);
}

// A medium's emission grid: a MEDIUM_GRID record of its own (density_scale =
// emission_scale, no majorant), which the medium names by Medium.emission_grid
dev::Medium compile_emission_grid(const MediumDesc& m, dev::SceneBuffers* b, std::vector<GridMemory>* grids) {
  dev::Medium e{};
  e.type = MEDIUM_GRID;
  e.density_scale = m.emission_scale;
  if (b->densities.size() + m.emission_grid.size() > size_t(UINT32_MAX))
    throw Error("the scene's density grids hold more than 2^32 values");
  e.grid_offset = uint32_t(b->densities.size());
  b->densities.insert(b->densities.end(), m.emission_grid.begin(), m.emission_grid.end());
  for (int k = 0; k < 3; ++k) {
    e.grid_size[k] = uint32_t(m.emission_grid_size[k]);
    e.grid_min[k] = m.emission_grid_min[k];
    e.grid_max[k] = m.emission_grid_max[k];
  }
  grids->push_back({"dense emission", m.emission_grid.size() * sizeof(float), 0});
  return e;
}

// Does a trilinear lookup of m's emission grid inside the world box [lo, hi] read a
// positive node?
bool emission_grid_positive_in(const MediumDesc& m, glm::dvec3 lo, glm::dvec3 hi) {
  int n0[3], n1[3];
  for (int k = 0; k < 3; ++k) {
    double lo_k = m.emission_grid_min[k], w = (double(m.emission_grid_max[k]) - lo_k) / (m.emission_grid_size[k] - 1);
    n0[k] = int(std::clamp(std::floor((lo[k] - lo_k) / w), 0.0, double(m.emission_grid_size[k] - 1)));
    n1[k] = int(std::clamp(std::ceil((hi[k] - lo_k) / w), 0.0, double(m.emission_grid_size[k] - 1)));
    if (hi[k] < lo_k || lo[k] > m.emission_grid_max[k]) return false;
  }
  for (int z = n0[2]; z <= n1[2]; ++z)
    for (int y = n0[1]; y <= n1[1]; ++y)
      for (int x = n0[0]; x <= n1[0]; ++x)
        if (m.emission_grid[(size_t(z) * m.emission_grid_size.y + y) * m.emission_grid_size.x + x] > 0.0f) return true;
  return false;
}

dev::Medium compile_medium(const MediumDesc& m, dev::SceneBuffers* b, std::vector<GridMemory>* grids) {
  dev::Medium d{};
  for (int c = 0; c < 3; ++c) {
    d.sigma_a[c] = m.sigma_a[c];
    d.sigma_s[c] = m.sigma_s[c];
    d.emission[c] = m.emission[c];
  }
  d.g = m.g;
  d.type = MEDIUM_HOMOGENEOUS;
  d.density_scale = m.density_scale;
  if (m.is_nanovdb()) {
    glm::vec3 sigma_t = m.sigma_a + m.sigma_s;
    // as for dense grids below: trilinear values never exceed the voxels they mix
    compile_nanovdb_grid(m, m.density_scale * std::max({sigma_t.x, sigma_t.y, sigma_t.z}) * 1.0001f, &d, b);
    grids->push_back({m.grid_source, m.nanovdb.size() * sizeof(uint32_t), m.majorant_density.size() * sizeof(float)});
  } else if (m.is_grid()) {
    d.type = MEDIUM_GRID;
    if (b->densities.size() + m.density.size() + kMajorantCells * kMajorantCells * kMajorantCells > size_t(UINT32_MAX))
      throw Error("the scene's density grids hold more than 2^32 values");
    d.grid_offset = uint32_t(b->densities.size());
    b->densities.insert(b->densities.end(), m.density.begin(), m.density.end());
    glm::vec3 sigma_t = m.sigma_a + m.sigma_s;
    // Bounds of sigma_t: trilinear values never exceed their largest node, and a little
    // margin keeps rounding from making a null-collision weight negative
    float scale = m.density_scale * std::max({sigma_t.x, sigma_t.y, sigma_t.z}) * 1.0001f;
    d.majorant = scale * *std::max_element(m.density.begin(), m.density.end());
    for (int k = 0; k < 3; ++k) {
      d.grid_size[k] = uint32_t(m.grid_size[k]);
      d.grid_min[k] = m.grid_min[k];
      d.grid_max[k] = m.grid_max[k];
    }
    // The majorant grid: up to kMajorantCells cells per axis splitting the box evenly, each
    // the largest node of the grid cells it overlaps
    glm::ivec3 cells = glm::min(m.grid_size - 1, glm::ivec3(kMajorantCells));
    d.majorant_offset = uint32_t(b->densities.size());
    for (int k = 0; k < 3; ++k) d.majorant_size[k] = uint32_t(cells[k]);
    auto node_range = [&](int axis, int c, int* lo, int* hi) {
      double n = m.grid_size[axis] - 1;
      *lo = int(std::floor(double(c) / cells[axis] * n));
      *hi = std::min(int(std::ceil(double(c + 1) / cells[axis] * n)), m.grid_size[axis] - 1);
    };
    glm::dvec3 cell_size = (glm::dvec3(m.grid_max) - glm::dvec3(m.grid_min)) / glm::dvec3(cells);
    bool emits_by_grid =
        m.has_emission_grid() && std::max({m.emission.x, m.emission.y, m.emission.z}) > 0.0f && m.emission_scale > 0.0f;
    float emission_rate = float(1.0 / std::min({cell_size.x, cell_size.y, cell_size.z}));
    for (int cz = 0; cz < cells.z; ++cz)
      for (int cy = 0; cy < cells.y; ++cy)
        for (int cx = 0; cx < cells.x; ++cx) {
          int x0, x1, y0, y1, z0, z1;
          node_range(0, cx, &x0, &x1);
          node_range(1, cy, &y0, &y1);
          node_range(2, cz, &z0, &z1);
          float peak = 0.0f;
          for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y)
              for (int x = x0; x <= x1; ++x)
                peak = std::max(peak, m.density[(size_t(z) * m.grid_size.y + y) * m.grid_size.x + x]);
          float sigma_bar = scale * peak;
          // Emission is gathered at tentative collisions only: where the emission grid is
          // positive the cell needs a positive rate even where the density is 0 (about one
          // tentative collision per cell crossed; the extra ones are null collisions)
          if (emits_by_grid && scale * peak < emission_rate) {
            glm::dvec3 lo = glm::dvec3(m.grid_min) + glm::dvec3(cx, cy, cz) * cell_size;
            if (emission_grid_positive_in(m, lo, lo + cell_size)) sigma_bar = emission_rate;
          }
          d.majorant = std::max(d.majorant, sigma_bar);
          b->densities.push_back(sigma_bar);
        }
    grids->push_back({"dense", m.density.size() * sizeof(float), size_t(cells.x) * cells.y * cells.z * sizeof(float)});
  }
  return d;
}

// media[GLOBAL_MEDIUM] is the scene's global medium (a vacuum record when it has none);
// then every MediumDesc; then, when needed, one vacuum record for the insides of clear solids
// (so that fog does not fill a glass ball). Material.medium is set for closed surfaces that
// rays cross: transmissive solids and null boundaries.
void compile_media(const Scene& scene, const SceneFeatures& f, dev::SceneBuffers* b, std::vector<GridMemory>* grids) {
  if (!f.media) return;  // the kernel reads neither buffer nor Material.medium
  for (const MediumDesc& m : scene.media)
    if (m.is_nanovdb() && !f.nanovdb)
      throw Error("compile_scene: the kernel features leave out NanoVDB grids the scene has");
  b->media.push_back(dev::Medium{});
  std::vector<dev::Medium> emission_grids;  // after every other record; Medium.emission_grid
  for (size_t i = 0; i < scene.media.size(); ++i) {
    b->media.push_back(compile_medium(scene.media[i], b, grids));
    if (scene.media[i].has_emission_grid()) {
      if (!scene.media[i].is_grid() || scene.media[i].is_nanovdb())
        throw Error("compile_scene: an emission grid needs a dense density grid beside it");
      emission_grids.push_back(compile_emission_grid(scene.media[i], b, grids));
      b->media.back().emission_grid = uint32_t(scene.media.size() + emission_grids.size());  // placeholder rank
    }
    if (int(i) == scene.global_medium) b->media[GLOBAL_MEDIUM] = b->media.back();  // its grid stored once
  }
  int vacuum = NO_MEDIUM;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const MaterialDesc& m = scene.materials[i];
    bool crossed = m.null_boundary || (m.transmission > 0.0f && !m.thin_walled);
    if (!crossed) continue;
    if (m.medium >= 0) {
      b->materials[i].medium = 1 + m.medium;
      continue;
    }
    if (vacuum == NO_MEDIUM) {
      vacuum = int(b->media.size());
      b->media.push_back(dev::Medium{});
    }
    b->materials[i].medium = vacuum;
  }
  // The emission grids' records go last: the placeholder N + k (N media) becomes the index
  // of the k-th one
  uint32_t first = uint32_t(b->media.size());
  for (dev::Medium& d : b->media)
    if (d.emission_grid != 0u) d.emission_grid = first + (d.emission_grid - uint32_t(scene.media.size()) - 1u);
  b->media.insert(b->media.end(), emission_grids.begin(), emission_grids.end());
}

glm::vec3 vertex(const dev::SceneBuffers& b, uint32_t v) {
  return glm::vec3(b.positions[3 * size_t(v)], b.positions[3 * size_t(v) + 1], b.positions[3 * size_t(v) + 2]);
}

// An environment map as a LIGHT_ENVIRONMENT: its texels appended to the float texel
// array as one more texture, its sampling CDFs as env_distribution (cl/lights/environment.cl).
// *power_scale gets its mean radiance luminance, strength included.
dev::Light compile_environment_map(const EnvironmentDesc& env, dev::SceneBuffers* b, double* power_scale) {
  const TextureDesc& t = env.image;
  if (t.width <= 0 || t.height <= 0 || t.rgbaf.size() != t.texels() * 4)
    throw Error("the environment map " + env.source + " has no float texels");
  if (b->texelsf.size() + t.texels() > size_t(UINT32_MAX) || b->textures.size() >= (size_t(1) << 24))
    throw Error("the scene's textures hold more than 2^32 texels");
  dev::TextureInfo info{};
  info.offset = uint32_t(b->texelsf.size());
  info.width = uint32_t(t.width);
  info.height = uint32_t(t.height);
  info.flags = WRAP_REPEAT | (WRAP_CLAMP << 8) | TEXTURE_FLOAT | TEXTURE_NEAREST;
  for (size_t i = 0; i < t.texels(); ++i)
    b->texelsf.push_back({{t.rgbaf[4 * i], t.rgbaf[4 * i + 1], t.rgbaf[4 * i + 2], 1.0f}});
  dev::Light l{};
  l.type = LIGHT_ENVIRONMENT;
  dev::EnvironmentLight& e = l.params.environment;
  e.map = float(b->textures.size());  // exact: fewer than 2^24 textures
  e.strength = env.strength;
  e.rotation = float(double(env.rotation) * kPi / 180.0);
  EnvironmentExtent extent = environment_extent(t, double(e.rotation));
  e.solid_angle = float(extent.solid_angle);
  for (int k = 0; k < 3; ++k) e.direction[k] = float(extent.direction[k]);
  e.integral = float(extent.integral);
  b->textures.push_back(info);
  b->env_distribution = environment_distribution(t);
  *power_scale = environment_mean_luminance(t) * env.strength;
  return l;
}

// A triangle light's bounding sphere for lights_triangle_omega_bound: TriangleLight.centre =
// its centroid in float, radius = the largest distance from that point to a corner, rounded
// up, so that the sphere holds the float corners the kernel sees
void set_triangle_bounding_sphere(const dev::SceneBuffers& b, const dev::Prim& p, dev::Light* l) {
  glm::dvec3 v[3] = {vertex(b, p.v[0]), vertex(b, p.v[1]), vertex(b, p.v[2])};
  glm::vec3 c = glm::vec3((v[0] + v[1] + v[2]) / 3.0);
  double r = 0.0;
  for (const glm::dvec3& x : v) r = std::max(r, glm::length(x - glm::dvec3(c)));
  for (int a = 0; a < 3; ++a) l->params.triangle.centre[a] = c[a];
  l->params.triangle.radius = std::nextafter(float(r * (1.0 + 1e-6)), INFINITY);
}

// Every emissive triangle, punctual light and the environment, with the selection table
// and the light tree over the finite ones (light_tree.hpp).
// Triangle lights come first, in increasing primitive order: the kernel finds the light of
// an emitter it hits by a binary search (lights_of_prim, cl/lights/lights.cl).
int compile_lights(const Scene& scene, dev::SceneBuffers* b) {
  std::vector<double> texture_mean(scene.textures.size(), -1.0);  // computed on first use
  std::vector<double> power;
  double radius = std::max(double(scene.bounds().radius()), 1e-6);
  for (size_t i = 0; i < b->prims.size(); ++i) {
    const dev::Prim& p = b->prims[i];
    const MaterialDesc& m = scene.materials[p.material];
    if (!(dev::luminance_rgb(m.emission.x, m.emission.y, m.emission.z) > 0.0f)) continue;
    double scale = 1.0;
    if (int tex = m.texture(TEX_EMISSION).index; tex != NO_TEXTURE) {
      if (texture_mean[size_t(tex)] < 0.0) texture_mean[size_t(tex)] = scene.textures[size_t(tex)].mean_luminance();
      scale = texture_mean[size_t(tex)];
    }
    double area;
    triangle_normal_area(vertex(*b, p.v[0]), vertex(*b, p.v[1]), vertex(*b, p.v[2]), &area);
    dev::Light l{};
    l.type = LIGHT_TRIANGLE;
    l.index = uint32_t(i);
    l.params.triangle.area = float(area);
    set_triangle_bounding_sphere(*b, p, &l);
    double w = light_power(l, *b, scale, radius);
    if (!(w > 0.0)) continue;  // includes emissive textures that are black throughout
    b->lights.push_back(l);
    power.push_back(w);
  }
  for (const PunctualLightDesc& p : scene.punctual_lights) {
    dev::Light l = punctual_light(p);
    double w = light_power(l, *b, 1.0, radius);
    if (!std::isfinite(w) || !std::isfinite(l.radiance[0] + l.radiance[1] + l.radiance[2]))
      throw Error("a punctual light's colour x intensity overflows single precision");
    if (!(w > 0.0)) continue;  // black or of zero intensity
    b->lights.push_back(l);
    power.push_back(w);
  }
  int environment = NO_LIGHT;
  if (scene.environment) {
    double power_scale = 0.0;
    dev::Light l = compile_environment_map(*scene.environment, b, &power_scale);
    if (power_scale > 0.0) {
      environment = int(b->lights.size());
      b->lights.push_back(l);
      power.push_back(light_power(l, *b, power_scale, radius));
    }
  } else if (dev::luminance_rgb(scene.background.x, scene.background.y, scene.background.z) > 0.0f) {
    dev::Light l{};
    l.type = LIGHT_ENVIRONMENT;
    l.params.environment.map = float(NO_TEXTURE);         // constant radiance
    l.params.environment.solid_angle = float(4.0 * kPi);  // the sphere, no direction
    l.params.environment.integral = float(4.0 * kPi);     // of a unit radiance over it
    for (int c = 0; c < 3; ++c) l.radiance[c] = scene.background[c];
    environment = int(b->lights.size());
    b->lights.push_back(l);
    power.push_back(light_power(l, *b, 1.0, radius));
  }
  std::vector<double> pmf;
  b->light_alias = alias_table(power, &pmf);
  for (size_t i = 0; i < b->lights.size(); ++i) b->lights[i].pmf = float(pmf[i]);
  LightTree tree = build_light_tree(*b, power, pmf);
  b->light_tree = std::move(tree.nodes);
  b->light_trails = std::move(tree.trails);
  return environment;
}

bool within_range(const glm::vec3& p) {  // false for NaN too
  return glm::all(glm::lessThanEqual(glm::abs(p), glm::vec3(kMaxCoordinate)));
}

// The geometry and the camera must fit single-precision rendering
void check_extent(const Scene& scene, const CameraDesc& camera) {
  Bounds b = scene.bounds();
  if (!b.empty() && !(within_range(b.lo) && within_range(b.hi)))
    throw Error("the scene extends beyond +-1e15 units, too far for single-precision rendering");
  if (scene.camera && !within_range(camera.position))  // one framing the scene lies within a few radii
    throw Error("the camera lies beyond +-1e15 units, too far for single-precision rendering");
  for (const PunctualLightDesc& l : scene.punctual_lights)
    if (!within_range(l.position))
      throw Error("a punctual light lies beyond +-1e15 units, too far for single-precision rendering");
  float forward = glm::length(camera.forward);
  if (!(forward > 0.0f && std::isfinite(forward)))
    throw Error("the camera has no viewing direction (its node transform is degenerate or not finite)");
}

}  // namespace

dev::Light punctual_light(const PunctualLightDesc& p) {
  dev::Light l{};
  l.type = p.type == PunctualType::Point ? LIGHT_POINT : p.type == PunctualType::Spot ? LIGHT_SPOT : LIGHT_DIRECTIONAL;
  for (int c = 0; c < 3; ++c) l.radiance[c] = p.color[c] * p.intensity;
  l.radiance[3] = p.type == PunctualType::Directional ? 0.0f : p.range;
  if (p.type == PunctualType::Point) {
    for (int c = 0; c < 3; ++c) l.params.point.position[c] = p.position[c];
  } else if (p.type == PunctualType::Spot) {
    for (int c = 0; c < 3; ++c) {
      l.params.spot.position[c] = p.position[c];
      l.params.spot.axis[c] = p.direction[c];
    }
    dev::SpotCone cone = dev::spot_cone(double(p.inner_cone), double(p.outer_cone));
    l.params.spot.cone_scale = cone.scale;
    l.params.spot.cone_offset = cone.offset;
  } else {
    for (int c = 0; c < 3; ++c) l.params.directional.direction[c] = p.direction[c];
  }
  return l;
}

std::vector<dev::AliasBin> alias_table(const std::vector<double>& weights, std::vector<double>* pmf) {
  const uint64_t range = uint64_t(1) << 32;
  size_t n = weights.size();
  pmf->assign(n, 0.0);
  if (n == 0) return {};
  if (n > (uint64_t(1) << 31)) throw Error("too many lights for the light table");
  double total = 0.0;
  for (double w : weights) total += w;
  // Vose's construction: bins below their share borrow the rest from one above it
  std::vector<double> q(n), keep(n, 1.0);
  std::vector<uint32_t> alias(n);
  std::vector<size_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    q[i] = weights[i] / total * double(n);
    alias[i] = uint32_t(i);
    (q[i] < 1.0 ? small : large).push_back(i);
  }
  while (!small.empty() && !large.empty()) {
    size_t s = small.back(), l = large.back();
    small.pop_back();
    keep[s] = q[s];
    alias[s] = uint32_t(l);
    q[l] -= 1.0 - q[s];
    if (q[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // Bin i holds the integers x in [ceil(i 2^32 / n), ceil((i + 1) 2^32 / n)); the low
  // words x n - i 2^32 of those are r_i, r_i + n, r_i + 2n, ... Count exactly how many
  // stay below the threshold: those select i, the others its alias.
  std::vector<dev::AliasBin> bins(n);
  std::vector<uint64_t> count(n, 0);
  auto bin_start = [&](uint64_t i) { return (i * range + n - 1) / n; };  // no overflow: i < 2^31
  for (size_t i = 0; i < n; ++i) {
    uint64_t start = bin_start(i), size = bin_start(i + 1) - start, r = start * n - i * range;
    uint64_t t = uint64_t(std::llround(keep[i] * double(range)));
    t = std::min<uint64_t>(t, range - 1);
    if (t <= r) t = r + 1;  // every light keeps at least one integer of its own
    uint64_t stay = std::min<uint64_t>(size, (t - r + n - 1) / n);
    bins[i] = {uint32_t(t), alias[i]};
    count[i] += stay;
    count[alias[i]] += size - stay;
  }
  for (size_t i = 0; i < n; ++i) (*pmf)[i] = double(count[i]) / double(range);
  return bins;
}

CompiledScene compile_scene(const Scene& scene, const FeaturesKnown& features_known) {
  return compile_scene(scene, scene.features(), features_known);
}

void CompiledScene::release_host_arrays() {
  auto lights = std::move(buffers.lights);
  buffers = dev::SceneBuffers();
  buffers.lights = std::move(lights);
}

CompiledScene compile_scene(const Scene& scene, const SceneFeatures& features, const FeaturesKnown& features_known) {
  auto start = Clock::now();
  CompiledScene c;
  c.features = features;
  const SceneFeatures needed = scene.features();
  if (!features.covers(needed)) throw Error("compile_scene: the kernel features leave out some the scene needs");
  check_extent(scene, resolve_camera(scene));
  compile_geometry(scene, c.features, &c.buffers);
  compile_materials(scene, &c.buffers);
  compile_textures(scene, &c.buffers);
  compile_media(scene, c.features, &c.buffers, &c.grids);
  c.environment_light = compile_lights(scene, &c.buffers);
  c.features.light_tree = features.light_tree || !c.buffers.light_tree.empty();  // a scene's need only known here
  c.buffers.camera_steps.push_back(dev::Camera{});  // motion blur: the image size's cameras, set by the app
  if (scene.motion_steps > 0) compile_motion(scene, &c.buffers);
  if (features_known) features_known(c);
  auto bvh_start = Clock::now();
  std::vector<bool> alpha_tested;
  for (const MaterialDesc& m : scene.materials) alpha_tested.push_back(m.alpha_tested());
  Bvh bvh = build_bvh(c.buffers.positions, c.buffers.prims, alpha_tested, 0, scene.motion_steps + 1);
  c.bvh_build_seconds = seconds_since(bvh_start);
  c.bvh_sah_cost = sah_cost(bvh);
  c.bvh_depth = bvh.depth;
  c.buffers.bvh_nodes = std::move(bvh.nodes);
  c.buffers.bvh_tris = std::move(bvh.tris);
  c.triangles = c.buffers.prims.size();
  c.vertices = c.buffers.positions.size() / 3 / size_t(scene.motion_steps + 1);
  c.device_bytes = c.buffers.bytes();
  c.compile_seconds = seconds_since(start);
  return c;
}

}  // namespace candela
