// Triangle meshes from OBJ and PLY files, for level-set colliders.
#pragma once

#include <string>
#include <string_view>

#include "fields/vdb/LevelSetCollider.h"

namespace tickfx::io {

/// Reads the triangles of an OBJ file (`v x y z` and `f` lines; a face of n > 3 corners is
/// fanned from its first; `v/vt/vn` and negative, relative indices are read; the rest is ignored)
/// or a PLY file (ascii or binary_little_endian / binary_big_endian, a `vertex` element with
/// float or double x, y, z and a `face` element with a list of int or uint indices), chosen by
/// the file's first bytes ("ply") or else as OBJ. Throws std::runtime_error beginning with `path`
/// for a missing, empty or truncated file, a bad number or index, or no triangles. What a mesh
/// must be to bound a solid is checked apart (meshProblem).
TriangleMesh readMeshFile(const std::string& path);

/// The same, from the file's bytes (`label` begins the messages): what the fuzzer drives.
TriangleMesh parseMesh(std::string_view bytes, const std::string& label);

}  // namespace tickfx::io
