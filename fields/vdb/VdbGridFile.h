// Reading one grid of a .vdb file, whole and safely: what VectorField and the VDB point caches
// share. Includes OpenVDB, so it stays out of the installed headers.
#pragma once

#include <openvdb/openvdb.h>

#include <string>

namespace tickfx {

/// "PATH: grid 'NAME'": how every message about a grid of a file begins.
std::string vdbGridLabel(const std::string& path, const std::string& grid);

/// Reads grid `name` of the .vdb file `path` completely (no delayed loading: the file may change
/// or vanish later, and a lazy read in a hot loop would need a lock). The file is read into memory
/// once and every byte of the grid checked (extractCheckedVdbGrid) before OpenVDB sees it, so a
/// corrupt or hostile file is an exception, never an abort in OpenVDB. Calls openvdb::initialize().
/// Throws std::runtime_error beginning with vdbGridLabel(path, name) for a missing file, a file
/// that is not OpenVDB, a truncated or corrupt file, a missing grid (naming the grids the file
/// has), a kind of grid tickfx does not read, and unreadable grid data.
openvdb::GridBase::Ptr readVdbGrid(const std::string& path, const std::string& name);

}  // namespace tickfx
