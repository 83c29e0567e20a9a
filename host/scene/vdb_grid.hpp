// Density grids from NanoVDB (.nvdb) and OpenVDB (.vdb) files. A grid goes to the device as
// its NanoVDB buffer (MEDIUM_NANOVDB, read by cl/media/nanovdb.cl), with majorant cells computed
// here from its tree.
#pragma once

#include <string>

#include "scene/scene.hpp"

namespace candela {

// True when candela was built with NanoVDB's headers (libnanovdb-dev)
bool nanovdb_supported();

// True when candela was built with OpenVDB (libopenvdb-dev) as well
bool openvdb_supported();

// Reads float grid `grid_name` (empty: the file's first grid) of the NanoVDB file at `path`
// into m's NanoVDB grid (MediumDesc::nanovdb, grid_min/grid_max, the majorant cells).
// The grid's index-to-world map may be any affine map. Throws candela::Error.
void load_nanovdb_density(const std::string& path, const std::string& grid_name, MediumDesc* m);

// The same for float grid `grid_name` (empty: the file's first float grid) of the OpenVDB
// file at `path`, converted with NanoVDB's openToNanoVDB. Throws candela::Error.
void load_openvdb_density(const std::string& path, const std::string& grid_name, MediumDesc* m);

}  // namespace candela
