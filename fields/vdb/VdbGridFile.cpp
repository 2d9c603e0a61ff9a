#include "fields/vdb/VdbGridFile.h"

#include <openvdb/io/Stream.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "fields/vdb/VdbFileCheck.h"

namespace tickfx {

std::string vdbGridLabel(const std::string& path, const std::string& grid) {
  return path + ": grid '" + grid + "'";
}

openvdb::GridBase::Ptr readVdbGrid(const std::string& path, const std::string& name) {
  const std::string label = vdbGridLabel(path, name);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw std::runtime_error(label + ": no such file");
  }
  // Read once: the bytes checked are the bytes OpenVDB reads, whoever rewrites the file meanwhile.
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw std::runtime_error(label + ": cannot read the file (" + std::strerror(errno) + ")");
  }
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) throw std::runtime_error(label + ": cannot read the file");
  openvdb::initialize();
  std::string stream;
  try {
    stream = extractCheckedVdbGrid(bytes, name);
  } catch (const VdbFileError& e) {
    switch (e.kind()) {
      case VdbFileError::Kind::NotVdb:
        throw std::runtime_error(label + ": cannot open the file as OpenVDB (" + e.what() + ")");
      case VdbFileError::Kind::NoSuchGrid:
        throw std::runtime_error(label + ": no such grid (" + e.what() + ")");
      case VdbFileError::Kind::Unreadable:
        break;
    }
    throw std::runtime_error(label + ": cannot read the grid (" + e.what() + ")");
  }
  bytes.clear();
  bytes.shrink_to_fit();
  openvdb::GridBase::Ptr grid;
  try {
    std::istringstream in(std::move(stream), std::ios::binary);
    openvdb::io::Stream vdb(in, /*delayLoad=*/false);
    const openvdb::GridPtrVecPtr grids = vdb.getGrids();
    if (grids && grids->size() == 1) grid = grids->front();
  } catch (const std::exception& e) {
    throw std::runtime_error(label + ": cannot read the grid (" + e.what() + ")");
  }
  if (!grid) throw std::runtime_error(label + ": cannot read the grid");
  return grid;
}

}  // namespace tickfx
