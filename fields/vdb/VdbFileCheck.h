// Checking an untrusted .vdb file before OpenVDB reads it. OpenVDB 10 trusts the sizes, counts and
// flags it reads: a corrupted one makes it abort on an assertion, read or write past a buffer, or
// allocate gigabytes. This walks one grid's bytes the way OpenVDB reads them and refuses anything
// OpenVDB would trust wrongly. Internal to tickfx_vdb: VdbGridFile.cpp is its one user.
//
// The checks are split as OpenVDB's readers are: VdbArchiveCheck.cpp (the file's header, metadata,
// transforms and grid descriptors; extractCheckedVdbGrid), VdbTreeCheck.h (a grid's tree and its
// compressed values), VdbPointsCheck.h (a PointDataGrid's leaves and attribute arrays), sharing
// the byte reader of VdbCheckReader.h.
#pragma once

#include <stdexcept>
#include <string>

namespace tickfx {

/// Why a file was refused; readVdbGrid words each kind as it words the same failure from OpenVDB.
class VdbFileError : public std::runtime_error {
 public:
  enum class Kind {
    NotVdb,      ///< not an OpenVDB file at all
    NoSuchGrid,  ///< the file has no grid of that name; what() lists the grids it has
    Unreadable,  ///< truncated, corrupt, or a kind of grid tickfx does not read
  };
  VdbFileError(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

/// Checks grid `name` of the .vdb file whose bytes are `file` and returns an OpenVDB stream (what
/// openvdb::io::Stream reads) holding that grid alone: a header, no file metadata, its descriptor,
/// and its bytes as they are in the file. Every byte OpenVDB reads from that stream has been
/// checked here, so reading it cannot abort or overrun a buffer, whatever the file holds.
///
/// Checked, mirroring OpenVDB 10.0's readers (io::Archive, io::File, MetaMap, math::Transform,
/// RootNode, InternalNode, LeafNode, io::readCompressedValues, points::PointDataLeafNode,
/// points::TypedAttributeArray, compression::PagedInputStream): every size against the bytes that
/// are left; metadata and attribute types against OpenVDB's registries and their sizes; every
/// blosc block with blosc_cbuffer_validate and against the size OpenVDB will take from it; node
/// masks and child orders as OpenVDB writes them; the passes, pages and attribute arrays of a
/// PointDataGrid. Being stricter than OpenVDB where OpenVDB's own writer is always stricter still
/// (unique names, tree nodes in order, the value mask written twice the same) keeps this short.
///
/// Reads file formats 222 (OpenVDB 3.0) to 224 (OpenVDB 10), and the grids tickfx uses: float,
/// double, int32, int64, vec3i, vec3s and vec3d trees (saved as half floats or not) and
/// PointDataGrids. Throws VdbFileError for anything else: another kind of grid, an instance grid,
/// a truncated or corrupt file ("the file is corrupt at byte N: WHAT").
std::string extractCheckedVdbGrid(const std::string& file, const std::string& name);

}  // namespace tickfx
