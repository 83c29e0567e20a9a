// Density grids from NanoVDB files (.nvdb), resampled into the dense node grid of a
// MediumDesc (cl/media.cl's trilinear lookup).
#pragma once

#include <string>

#include "scene.hpp"

namespace candela {

// True when candela was built with NanoVDB's headers (libnanovdb-dev)
bool nanovdb_supported();

// Reads float grid `grid_name` (empty: the file's first grid) of the NanoVDB file at `path`
// into m's grid: one node per voxel of the grid's active bounding box and one node of the
// background value around it, placed by the grid's index-to-world map (scale and
// translation; rotated grids are an error). Throws candela::Error.
void load_nanovdb_density(const std::string& path, const std::string& grid_name, MediumDesc* m);

}  // namespace candela
