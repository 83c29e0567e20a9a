// candela's media extras: absorption, scattering and emission coefficients, and density
// grids (inline dense ones, NanoVDB and OpenVDB files).
#include <cmath>
#include <filesystem>

#include "base/error.hpp"
#include "gltf/reader.hpp"
#include "scene/vdb_grid.hpp"

namespace candela::gltf {
namespace {

// A dense grid {"size": [nx, ny, nz], "min": [x, y, z], "max": [x, y, z], key: [nx ny nz
// values, x fastest]} (gw names it in errors)
void read_dense_grid(const tinygltf::Value& grid, const std::string& gw, const char* key, glm::ivec3* size,
                     glm::vec3* lo, glm::vec3* hi, std::vector<float>* values) {
  if (!grid.IsObject()) throw Error(gw + " must be an object");
  size_t count = 1;
  for (int k = 0; k < 3; ++k) {
    double n = number_or(grid, "size", k, 0.0);
    if (!(n >= 2.0 && n <= 1024.0) || n != std::floor(n)) throw Error(gw + ".size must hold 3 integers in [2, 1024]");
    (*size)[k] = int(n);
    count *= size_t(n);
    (*lo)[k] = float(number_or(grid, "min", k, NAN));
    (*hi)[k] = float(number_or(grid, "max", k, NAN));
    if (!((*lo)[k] < (*hi)[k]) || !std::isfinite((*lo)[k]) || !std::isfinite((*hi)[k]))
      throw Error(gw + ": min and max must be finite with min < max on every axis");
  }
  if (!grid.Has(key) || !grid.Get(key).IsArray() || grid.Get(key).ArrayLen() != count)
    throw Error(gw + "." + key + " must be an array of size[0] x size[1] x size[2] numbers");
  const tinygltf::Value& d = grid.Get(key);
  values->resize(count);
  for (size_t i = 0; i < count; ++i) {
    const tinygltf::Value& x = d.Get(int(i));
    (*values)[i] = x.IsNumber() ? float(x.GetNumberAsDouble()) : -1.0f;
    if (!((*values)[i] >= 0.0f) || !std::isfinite((*values)[i]))
      throw Error(gw + "." + key + " must hold finite non-negative numbers");
  }
}

// "emission_grid": a dense grid ("values" in place of "density") scaling the emission, its
// box inside the density grid's (where the majorant cells are)
void read_emission_grid(const tinygltf::Value& v, const std::string& where, MediumDesc* m) {
  if (!v.Has("emission_grid")) return;
  std::string ew = where + ".emission_grid";
  read_dense_grid(v.Get("emission_grid"), ew, "values", &m->emission_grid_size, &m->emission_grid_min,
                  &m->emission_grid_max, &m->emission_grid);
  for (int k = 0; k < 3; ++k)
    if (m->emission_grid_min[k] < m->grid_min[k] || m->emission_grid_max[k] > m->grid_max[k])
      throw Error(ew + ": its box must lie inside the density grid's box (min " + std::to_string(m->grid_min[k]) +
                  ", max " + std::to_string(m->grid_max[k]) + " on axis " + std::to_string(k) + ")");
}

// [r, g, b] of finite non-negative numbers at v[key], if there
void read_rgb(const tinygltf::Value& v, const std::string& where, const char* key, glm::vec3* out) {
  if (!v.Has(key)) return;
  const tinygltf::Value& a = v.Get(key);
  if (!a.IsArray() || a.ArrayLen() != 3) throw Error(where + "." + key + " must be an array of 3 numbers");
  for (int c = 0; c < 3; ++c) {
    (*out)[c] = float(number_or(v, key, c, -1.0));
    if (!((*out)[c] >= 0.0f) || !std::isfinite((*out)[c]))
      throw Error(where + "." + key + " must hold finite non-negative numbers");
  }
}

// sigma_a, sigma_s, emission, g, density_scale, emission_scale
void read_coefficients(const tinygltf::Value& v, const std::string& where, MediumDesc* m) {
  read_rgb(v, where, "sigma_a", &m->sigma_a);
  read_rgb(v, where, "sigma_s", &m->sigma_s);
  read_rgb(v, where, "emission", &m->emission);
  m->g = float(number_or(v, "g", -1, 0.0));
  if (!(std::fabs(m->g) < 1.0f)) throw Error(where + ".g must lie in (-1, 1)");
  m->density_scale = float(number_or(v, "density_scale", -1, 1.0));
  if (!(m->density_scale >= 0.0f) || !std::isfinite(m->density_scale))
    throw Error(where + ".density_scale must be finite and non-negative");
  if (v.Has("emission_scale")) {
    m->emission_scale = float(number_or(v, "emission_scale", -1, -1.0));
    if (!(m->emission_scale >= 0.0f) || !std::isfinite(m->emission_scale))
      throw Error(where + ".emission_scale must be finite and non-negative");
    if (!v.Has("emission_grid")) throw Error(where + ".emission_scale needs an emission_grid");
  }
}

// {"nanovdb": "file.nvdb"} or {"vdb": "file.vdb"}, relative to the glTF file, and "name": a
// grid; false when the grid names no file
bool read_grid_file(const tinygltf::Value& grid, const std::string& gw, const SceneFolder& folder, MediumDesc* m) {
  for (const char* key : {"nanovdb", "vdb"}) {
    if (!grid.Has(key)) continue;
    const tinygltf::Value& file = grid.Get(key);
    if (!file.IsString() || file.Get<std::string>().empty()) throw Error(gw + "." + key + " must name a file");
    if (grid.Has("name") && !grid.Get("name").IsString()) throw Error(gw + ".name must be a string");
    std::string name = grid.Has("name") ? grid.Get("name").Get<std::string>() : "";
    std::filesystem::path path = folder.resolve(file.Get<std::string>(), gw + "." + key);
    if (std::string(key) == "vdb")
      load_openvdb_density(path.string(), name, m);
    else
      load_nanovdb_density(path.string(), name, m);
    return true;
  }
  return false;
}

}  // namespace

// A medium from candela's extras: {"sigma_a": [r, g, b], "sigma_s": [r, g, b], "g": g,
// "emission": [r, g, b], "density_scale": s, "grid": {"size": [nx, ny, nz], "min": [x, y, z],
// "max": [x, y, z], "density": [nx ny nz values, x fastest]} or {"nanovdb": "f.nvdb"} or
// {"vdb": "f.vdb"} with an optional "name"}, "emission_grid": {"size", "min", "max", "values"}
// (with a dense grid) and "emission_scale": s; every entry optional
MediumDesc read_medium(const tinygltf::Value& v, const std::string& where, const SceneFolder& folder) {
  if (!v.IsObject()) throw Error(where + " must be an object");
  MediumDesc m;
  read_coefficients(v, where, &m);
  if (v.Has("emission_grid") && (!v.Has("grid") || !v.Get("grid").IsObject() || !v.Get("grid").Has("size")))
    throw Error(where + ".emission_grid needs an inline dense grid (size, min, max, density) beside it");
  if (!v.Has("grid")) return m;
  const tinygltf::Value& grid = v.Get("grid");
  std::string gw = where + ".grid";
  if (read_grid_file(grid, gw, folder, &m)) return m;
  read_dense_grid(grid, gw, "density", &m.grid_size, &m.grid_min, &m.grid_max, &m.density);
  read_emission_grid(v, where, &m);
  return m;
}

}  // namespace candela::gltf
