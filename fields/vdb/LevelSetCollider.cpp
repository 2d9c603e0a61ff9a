#include "fields/vdb/LevelSetCollider.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "fields/ShapeCollider.h"
#include "fields/vdb/RegisteredGrid.h"
#include "fields/vdb/VdbGridFile.h"

namespace tickfx {
namespace {

using collide::V3;
using Accessor = openvdb::tree::ValueAccessor<const openvdb::FloatTree, /*IsSafe=*/false>;
constexpr float kHalfWidth = 3.0f;  // voxels of narrow band each side of a baked surface
// OpenVDB's coordinates are 32-bit: a grid whose voxels would lie farther out than this from the
// origin (in voxels) is refused rather than wrapped.
constexpr double kIndexReach = 0x1p30;

void checkIndexReach(double extentInVoxels, const std::string& what) {
  if (!(extentInVoxels < kIndexReach)) {
    throw std::runtime_error(what + " lies " + settingNumber(std::floor(extentInVoxels)) +
                             " voxels from the origin (at most 2^30: a larger voxel_size, or "
                             "the shape nearer the origin)");
  }
}

// A signed-distance grid sampled in float: index = (x − origin) / voxel, trilinear over the
// eight voxels around it, the weights and sums in a fixed order (no double: one precision).
// Tells grids apart for the accessors cached per thread (an address may be reused by a later grid).
std::atomic<std::uint64_t> gNextGridSerial{1};

struct LevelSetShape {
  openvdb::FloatGrid::ConstPtr grid;
  std::uint64_t serial = 0;  // gNextGridSerial's, when the grid was given to a shape
  V3 origin;                 // world position of voxel (0, 0, 0)
  float voxel = 1;           // edge, metres
  float inverse = 1;         // 1 / voxel
  float radius = 0;          // the particles'
  bool container = false;
  V3 lo, hi;  // world box of the active voxels, grown by the band, radius and a voxel

  float sdf(const Accessor& acc, const V3& x) const {
    const V3 u = (x - origin) * inverse;
    const float fx = std::floor(u.x()), fy = std::floor(u.y()), fz = std::floor(u.z());
    const float tx = u.x() - fx, ty = u.y() - fy, tz = u.z() - fz;
    // Far outside the index range a float does not fit an int: clamp (the value is background).
    const auto index = [](float f) {
      return static_cast<openvdb::Int32>(std::clamp(f, -1.0e9f, 1.0e9f));
    };
    const openvdb::Int32 i = index(fx), j = index(fy), k = index(fz);
    // The cell's eight corners: from one leaf's buffer when the cell lies in one leaf (7 cells
    // in 8 along each axis), one probe instead of eight lookups; else through the accessor.
    float v[2][2][2];
    using Leaf = openvdb::FloatTree::LeafNodeType;
    const openvdb::Coord ijk(i, j, k);
    const Leaf* leaf = nullptr;
    constexpr openvdb::Int32 kLast = Leaf::DIM - 1;
    if ((i & kLast) != kLast && (j & kLast) != kLast && (k & kLast) != kLast)
      leaf = acc.probeConstLeaf(ijk);
    if (leaf != nullptr) {
      const openvdb::Index o = Leaf::coordToOffset(ijk);
      constexpr openvdb::Index dx = Leaf::DIM * Leaf::DIM, dy = Leaf::DIM, dz = 1;
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          for (int c = 0; c < 2; ++c)
            v[a][b][c] = leaf->getValue(o + static_cast<openvdb::Index>(a) * dx +
                                        static_cast<openvdb::Index>(b) * dy +
                                        static_cast<openvdb::Index>(c) * dz);
    } else {
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          for (int c = 0; c < 2; ++c) v[a][b][c] = acc.getValue(ijk.offsetBy(a, b, c));
    }
    const auto at = [&](int di, int dj, int dk) { return v[di][dj][dk]; };
    const float c00 = at(0, 0, 0) + (at(1, 0, 0) - at(0, 0, 0)) * tx;
    const float c10 = at(0, 1, 0) + (at(1, 1, 0) - at(0, 1, 0)) * tx;
    const float c01 = at(0, 0, 1) + (at(1, 0, 1) - at(0, 0, 1)) * tx;
    const float c11 = at(0, 1, 1) + (at(1, 1, 1) - at(0, 1, 1)) * tx;
    const float c0 = c00 + (c10 - c00) * ty;
    const float c1 = c01 + (c11 - c01) * ty;
    return c0 + (c1 - c0) * tz;
  }
  float phi(const Accessor& acc, const V3& x) const {
    const float d = sdf(acc, x);
    return (container ? -d : d) - radius;
  }
  // This thread's accessor of the grid, its node cache kept from call to call (OpenVDB's way:
  // an accessor a thread; unregistered, so it costs the tree nothing).
  const Accessor& accessor() const {
    thread_local std::uint64_t cachedSerial = 0;
    thread_local std::optional<Accessor> cached;
    if (cachedSerial != serial) {
      cached.emplace(grid->tree());
      cachedSerial = serial;
    }
    return *cached;
  }
  float phi(const V3& x) const { return phi(accessor(), x); }
  V3 normalAt(const V3& x) const {
    const Accessor& acc = accessor();
    const float h = 0.5f * voxel;
    V3 g;
    for (int c = 0; c < 3; ++c) {
      V3 p = x, m = x;
      p[c] += h;
      m[c] -= h;
      g[c] = sdf(acc, p) - sdf(acc, m);
    }
    if (container) g = -g;
    const float l = collide::length(g);
    return l > 0.0f ? V3(g / l) : V3(0.0f, 1.0f, 0.0f);
  }
  bool touchesBox(const V3& a, const V3& b) const { return collide::boxesMeet(a, b, lo, hi); }
  // A container's outside is everywhere beyond its box: every path is tested.
  bool mayTouch(const V3& a, const V3& b) const { return container || touchesBox(a, b); }
  bool screenBox(V3& below, V3& above) const {
    below = lo;
    above = hi;
    return !container;
  }
  bool entry(const V3& a, const V3& b, float tolerance, collide::Entry& e) const {
    // An obstacle's outside beyond its box is background (positive): nothing to find. A
    // container's is forbidden everywhere there, so it is always marched.
    if (!container && !touchesBox(a, b)) return false;
    const Accessor& acc = accessor();
    const float pa = phi(acc, a);
    if (pa < -tolerance) {
      e.s = 0.0f;
      return true;
    }
    const V3 d = b - a;
    const float length = collide::length(d);
    if (!(length > 0.0f)) return false;
    const float half = 0.5f * voxel;
    float s0 = 0.0f, p0 = pa;
    while (s0 < 1.0f) {
      // Half a voxel near the surface; farther away, half the value: trilinear interpolation of
      // distances changes by at most √3 per metre, so phi cannot reach 0 within it.
      const float step = std::max(half, 0.5f * p0);
      const float s1 = std::min(1.0f, s0 + step / length);
      const float p1 = phi(acc, a + d * s1);
      if (p1 < -tolerance) {
        // The crossing lies in (s0, s1], where phi is all but linear (at most half a voxel, or a
        // stretch of guaranteed distance): four steps of regula falsi (Illinois) towards it, then
        // the contact is settled on the surface along its normal.
        float outer = s0, inner = s1, pOuter = p0, pInner = p1, wOuter = p0;
        for (int k = 0; k < 4 && pOuter > 0.0f; ++k) {
          const float mid = outer + (inner - outer) * (wOuter / (wOuter - pInner));
          if (!(mid > outer && mid < inner)) break;
          const float pm = phi(acc, a + d * mid);
          if (pm < 0.0f) {
            inner = mid;
            pInner = pm;
            wOuter *= 0.5f;  // Illinois: the stale end's weight halved
          } else {
            outer = mid;
            pOuter = wOuter = pm;
          }
        }
        e.s = outer;
        // < 0: pInner < 0 <= pOuter, or pInner < -tolerance <= pOuter.
        e.slope = (pInner - pOuter) / ((inner - outer) * length);
        return true;
      }
      s0 = s1;
      p0 = p1;
    }
    return false;
  }
};

float baked(const LevelSetSettings& l, const Eigen::Vector3d& x) {
  const Eigen::Vector3d p = x - l.center;
  switch (l.shape) {
    case LevelSetSettings::Shape::Sphere:
      return static_cast<float>(p.norm() - l.radius);
    case LevelSetSettings::Shape::Box: {
      const Eigen::Vector3d q = p.cwiseAbs() - l.size * 0.5;
      return static_cast<float>(q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0));
    }
    case LevelSetSettings::Shape::Torus: {
      const double ring = std::hypot(p.x(), p.z()) - l.majorRadius;
      return static_cast<float>(std::hypot(ring, p.y()) - l.minorRadius);
    }
  }
  return 0.0f;
}

// Half the edges of the box around the analytic shape, centred on l.center.
Eigen::Vector3d bakeExtent(const LevelSetSettings& l) {
  if (l.shape == LevelSetSettings::Shape::Sphere) return Eigen::Vector3d::Constant(l.radius);
  if (l.shape == LevelSetSettings::Shape::Box) return l.size * 0.5;
  const double across = l.majorRadius + l.minorRadius;  // the torus, about y
  return {across, l.minorRadius, across};
}

// The analytic shape's distance at every voxel within the band of its surface, then the sign
// of the rest filled in (OpenVDB's signed flood fill): one thread, in a fixed order.
openvdb::FloatGrid::Ptr bake(const LevelSetSettings& l) {
  const double h = l.voxelSize;
  const float band = kHalfWidth * static_cast<float>(h);
  auto grid = newRegisteredGrid<openvdb::FloatGrid>(band);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  const Eigen::Vector3d extent = bakeExtent(l);
  const Eigen::Vector3d lo = (l.center - extent) / h, hi = (l.center + extent) / h;
  checkIndexReach(std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff()), "bake: the shape");
  const double voxels = (hi - lo + Eigen::Vector3d::Constant(2.0 * kHalfWidth + 2.0)).prod();
  if (!(voxels < 2.0e8)) {
    throw std::runtime_error("bake: voxel_size " + settingNumber(h) + " makes " +
                             settingNumber(std::floor(voxels)) +
                             " voxels to visit (at most 200000000: a larger voxel_size)");
  }
  auto acc = grid->getAccessor();
  const int pad = static_cast<int>(kHalfWidth) + 1;
  for (int i = static_cast<int>(std::floor(lo.x())) - pad;
       i <= static_cast<int>(std::ceil(hi.x())) + pad; ++i) {
    for (int j = static_cast<int>(std::floor(lo.y())) - pad;
         j <= static_cast<int>(std::ceil(hi.y())) + pad; ++j) {
      for (int k = static_cast<int>(std::floor(lo.z())) - pad;
           k <= static_cast<int>(std::ceil(hi.z())) + pad; ++k) {
        const float d = baked(l, Eigen::Vector3d(i, j, k) * h);
        if (std::fabs(d) < band) acc.setValue(openvdb::Coord(i, j, k), d);
      }
    }
  }
  openvdb::tools::signedFloodFill(grid->tree(), /*threaded=*/false);
  return grid;
}

openvdb::FloatGrid::Ptr fromMesh(const LevelSetSettings& l, const TriangleMesh& mesh) {
  if (const std::string p = meshProblem(mesh); !p.empty()) {
    throw std::runtime_error(l.mesh + ": " + p);
  }
  double reach = 0.0;
  for (const Eigen::Vector3f& p : mesh.points)
    reach = std::max(reach, double(p.cwiseAbs().maxCoeff()));
  checkIndexReach(reach / l.voxelSize + kHalfWidth, l.mesh + ": the mesh");
  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.points.size());
  for (const Eigen::Vector3f& p : mesh.points) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  const auto xform = openvdb::math::Transform::createLinearTransform(l.voxelSize);
  // meshToLevelSet works in index space, in parallel; each voxel's distance is computed from the
  // triangles alone, so the grid is the same on any thread count.
  return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, points, triangles, kHalfWidth);
}

openvdb::FloatGrid::Ptr fromFile(const LevelSetSettings& l) {
  openvdb::GridBase::Ptr base = readVdbGrid(l.path, l.grid);
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid) {
    throw std::runtime_error(vdbGridLabel(l.path, l.grid) + ": holds " + base->valueType() +
                             " values (" + base->type() + "); a level set needs float");
  }
  return grid;
}

LevelSetShape shapeOf(const ColliderSettings& s, openvdb::FloatGrid::Ptr grid,
                      const std::string& label) {
  const openvdb::math::Transform& xf = grid->transform();
  const openvdb::Vec3d vs = xf.voxelSize();
  const openvdb::math::AffineMap::Ptr map = xf.baseMap()->getAffineMap();
  const openvdb::Mat4d m = map->getMat4();
  const bool axisAligned = xf.isLinear() && m(0, 1) == 0.0 && m(0, 2) == 0.0 && m(1, 0) == 0.0 &&
                           m(1, 2) == 0.0 && m(2, 0) == 0.0 && m(2, 1) == 0.0 && m(0, 0) > 0.0 &&
                           m(0, 0) == m(1, 1) && m(1, 1) == m(2, 2);
  if (!axisAligned) {
    throw std::runtime_error(label +
                             ": the grid's transform is not a translation and one voxel "
                             "size (voxels " +
                             settingNumber(vs.x()) + " x " + settingNumber(vs.y()) + " x " +
                             settingNumber(vs.z()) +
                             "); a level set collider needs cubic, axis-aligned voxels");
  }
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  if (box.empty()) throw std::runtime_error(label + ": the grid has no active voxel");
  LevelSetShape shape;
  shape.voxel = static_cast<float>(vs.x());
  shape.inverse = static_cast<float>(1.0 / vs.x());
  const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0.0));
  shape.origin =
      V3(static_cast<float>(o.x()), static_cast<float>(o.y()), static_cast<float>(o.z()));
  shape.radius = static_cast<float>(s.particleRadius);
  shape.container = s.side == ColliderSide::Inside;
  const float grow = shape.radius + shape.voxel;
  const openvdb::Vec3d lo = xf.indexToWorld(box.min().asVec3d());
  const openvdb::Vec3d hi = xf.indexToWorld(box.max().asVec3d());
  for (int c = 0; c < 3; ++c) {
    shape.lo[c] = static_cast<float>(lo[c]) - grow;
    shape.hi[c] = static_cast<float>(hi[c]) + grow;
  }
  shape.grid = grid;
  shape.serial = gNextGridSerial.fetch_add(1, std::memory_order_relaxed);
  return shape;
}

}  // namespace

std::string meshProblem(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return "has no triangles";
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c) {
      if (tri[c] >= mesh.points.size()) {
        return "triangle " + std::to_string(t) + " uses vertex " + std::to_string(tri[c]) + " of " +
               std::to_string(mesh.points.size());
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      return "triangle " + std::to_string(t) + " repeats a vertex";
    }
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  }
  for (const auto& [edge, uses] : edges) {
    if (uses != 2) {
      return "is not closed: the edge between vertices " + std::to_string(edge.first) + " and " +
             std::to_string(edge.second) + " belongs to " + std::to_string(uses) +
             (uses == 1 ? " triangle" : " triangles") + " (expected 2)";
    }
  }
  return {};
}

std::unique_ptr<Collider> makeLevelSetCollider(const ColliderSettings& s,
                                               const TriangleMesh* mesh) {
  throwIfAny("level_set collider", s.validate());
  if (s.type != ColliderType::LevelSet) {
    throw std::invalid_argument("makeLevelSetCollider: the settings are not a level set's");
  }
  openvdb::initialize();
  const LevelSetSettings& l = s.levelSet;
  openvdb::FloatGrid::Ptr grid;
  std::string label;
  switch (l.source) {
    case LevelSetSettings::Source::File:
      grid = fromFile(l);
      label = vdbGridLabel(l.path, l.grid);
      break;
    case LevelSetSettings::Source::Mesh:
      if (mesh == nullptr) throw std::invalid_argument("makeLevelSetCollider: no mesh given");
      grid = fromMesh(l, *mesh);
      label = l.mesh;
      break;
    case LevelSetSettings::Source::Bake:
      grid = bake(l);
      label = "bake";
      break;
  }
  return std::make_unique<collide::ShapeCollider<LevelSetShape>>(s, shapeOf(s, grid, label));
}

std::optional<LevelSetInfo> levelSetInfo(const Collider& collider) {
  const auto* c = dynamic_cast<const collide::ShapeCollider<LevelSetShape>*>(&collider);
  if (c == nullptr) return std::nullopt;
  return LevelSetInfo{c->shape().voxel, c->shape().lo, c->shape().hi};
}

}  // namespace tickfx
