// libFuzzer target: io::parseMesh, the OBJ and PLY reader of level-set colliders, then the closed
// mesh check and, for a small closed mesh, the level set made from it. Any input must give a mesh
// or the reader's std::runtime_error, nothing else; every index of a mesh read is a point's.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "fields/vdb/LevelSetCollider.h"
#include "io/mesh/MeshFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const tickfx::TriangleMesh mesh = tickfx::io::parseMesh(bytes, "fuzz.mesh");
    if (!tickfx::meshProblem(mesh).empty()) return 0;
    for (const auto& t : mesh.triangles) {
      for (const std::uint32_t i : t) {
        if (i >= mesh.points.size()) __builtin_trap();  // a closed mesh past its points
      }
    }
    if (mesh.triangles.size() > 64) return 0;
    // A coarse grid over the mesh's own extent: what a collider would make of it.
    Eigen::Vector3f lo = mesh.points[0], hi = mesh.points[0];
    for (const auto& p : mesh.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const float extent = (hi - lo).maxCoeff();
    if (!(extent > 1e-3f && extent < 100.0f)) return 0;
    tickfx::ColliderSettings s;
    s.type = tickfx::ColliderType::LevelSet;
    s.levelSet.source = tickfx::LevelSetSettings::Source::Mesh;
    s.levelSet.mesh = "fuzz.mesh";
    s.levelSet.voxelSize = extent / 8.0f;
    tickfx::makeLevelSetCollider(s, &mesh);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
