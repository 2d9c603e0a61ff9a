#include "fields/vdb/VectorField.h"

#include "fields/vdb/VdbGridFile.h"
#include "fields/vdb/VectorFieldGrids.h"
#include "particles/ExactTime.h"
#include "particles/ParallelFor.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace tickfx {

std::string sequenceFramePath(const std::string& pattern, int frame, int padding) {
  const std::string key = "{frame}";
  const std::size_t at = pattern.find(key);
  if (at == std::string::npos) return pattern;
  std::string number = std::to_string(frame < 0 ? -static_cast<long long>(frame) : frame);
  if (number.size() < static_cast<std::size_t>(padding)) {
    number.insert(0, static_cast<std::size_t>(padding) - number.size(), '0');
  }
  if (frame < 0) number.insert(0, 1, '-');
  std::string path = pattern;
  path.replace(at, key.size(), number);
  return path;
}

namespace {

// The name of frame `frame` in messages and, for files, the file to load.
std::string framePath(const VectorField::Settings& s, int frame) {
  if (!(s.fps > 0.0)) return s.file;
  if (s.file.find("{frame}") == std::string::npos) {  // grids made in memory
    return s.file + " (frame " + std::to_string(frame) + ")";
  }
  return sequenceFramePath(s.file, frame, s.framePadding);
}

Eigen::Vector3f toFloat(const openvdb::Vec3f& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Vector3f toFloat(const openvdb::Vec3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

/// openvdb::tools::BoxSampler's result bit for bit, for samples that come in leaf order
/// (integrators/LeafOrder.h): consecutive samples, and an advection step's stages, mostly read
/// the same leaves. BoxSampler reads the eight corners of a cell with eight accessor probes (a
/// cell across leaves, one in three for scattered points, alternates between them and misses the
/// accessor's leaf cache at each); this keeps the 2 × 2 × 2 leaves from the last sample's leaf
/// on, each looked up once, on first use, until a sample falls in another leaf. A corner is then
/// one load from a leaf's buffer, or from the one value of a tile or the background where no leaf
/// is allocated (a leaf-sized region without a leaf lies in one tile of the tree, or in none: its
/// value and active state are the same throughout, as the accessor would read them). The corners
/// are then interpolated by BoxSampler's own function. One per thread and frame, as an accessor.
template <class GridT>
class LeafNeighbourhood {
 public:
  using Accessor = typename GridT::ConstUnsafeAccessor;
  using Leaf = typename GridT::TreeType::LeafNodeType;
  using ValueT = typename GridT::ValueType;

  /// Asks the processor for the cache lines of the cell at `index` where it lies in the leaf
  /// the neighbourhood is anchored at (a later sample's, as samples come in leaf order): a
  /// sample's cost is the memory latency of its corners.
  void prefetch(const openvdb::Vec3d& index) const {
    const openvdb::Coord base(openvdb::tools::local_util::floorVec3(index));
    if ((base & ~static_cast<openvdb::Int32>(Leaf::DIM - 1)) != origin_ || (fetched_ & 1u) == 0 ||
        leaf_[0] == nullptr) {
      return;
    }
    const ValueT* corner = values_[0] + Leaf::coordToOffset(base);
    constexpr std::size_t kRow = Leaf::DIM, kPlane = Leaf::DIM * Leaf::DIM;
    __builtin_prefetch(corner);
    __builtin_prefetch(corner + kRow);
    __builtin_prefetch(corner + kPlane);
    __builtin_prefetch(corner + kPlane + kRow);
  }

  /// BoxSampler::sample(acc, index, result)'s result into `result`, and true; or, with
  /// `zeroOutside` where the voxel nearest to `index` is inactive (!acc.isValueOn(
  /// Coord::round(index))), false and nothing sampled.
  bool sample(Accessor& acc, const openvdb::Vec3d& index, bool zeroOutside, ValueT& result) {
    const openvdb::Vec3i base = openvdb::tools::local_util::floorVec3(index);
    const openvdb::Coord ijk(base);
    anchor(ijk);
    if (zeroOutside && !active(acc, openvdb::Coord::round(index))) return false;
    ValueT data[2][2][2];
    const openvdb::Coord local = ijk - origin_;
    constexpr openvdb::Int32 kLast = static_cast<openvdb::Int32>(Leaf::DIM) - 1;
    if (local.x() < kLast && local.y() < kLast && local.z() < kLast && neighbour(acc, ijk) == 0 &&
        leaf_[0] != nullptr) {
      // The cell inside the anchored leaf (7³ of its 8³ cells): its corners at fixed offsets.
      const ValueT* v = values_[0] + Leaf::coordToOffset(ijk);
      constexpr std::size_t kRow = Leaf::DIM, kPlane = Leaf::DIM * Leaf::DIM;
      data[0][0][0] = v[0];
      data[0][0][1] = v[1];
      data[0][1][0] = v[kRow];
      data[0][1][1] = v[kRow + 1];
      data[1][0][0] = v[kPlane];
      data[1][0][1] = v[kPlane + 1];
      data[1][1][0] = v[kPlane + kRow];
      data[1][1][1] = v[kPlane + kRow + 1];
    } else {
      for (int a = 0; a < 2; ++a) {
        for (int b = 0; b < 2; ++b) {
          for (int c = 0; c < 2; ++c) data[a][b][c] = value(acc, ijk.offsetBy(a, b, c));
        }
      }
    }
    result = openvdb::tools::BoxSampler::trilinearInterpolation(data, index - base);
    return true;
  }

 private:
  static constexpr int kLog2Dim = static_cast<int>(Leaf::LOG2DIM);

  // Makes the neighbourhood that of the leaf holding `voxel`, nothing looked up yet, unless it is.
  void anchor(const openvdb::Coord& voxel) {
    const openvdb::Coord origin = voxel & ~static_cast<openvdb::Int32>(Leaf::DIM - 1);
    if (origin == origin_) return;
    origin_ = origin;
    fetched_ = 0;
  }

  // Which of the eight leaves holds `voxel` (x, y, z one bit each, x highest), looked up now if
  // it was not yet; −1 beyond them (no sample's corners are: only an index too large for an int
  // brings one there, and then the accessor answers).
  int neighbour(Accessor& acc, const openvdb::Coord& voxel) {
    int n = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const std::int64_t d = std::int64_t{voxel[axis]} - origin_[axis];
      if (d < 0 || d >= 2 * std::int64_t{Leaf::DIM}) return -1;
      n = (n << 1) | static_cast<int>(d >> kLog2Dim);
    }
    if ((fetched_ & (1u << n)) == 0) fetch(acc, n);
    return n;
  }

  void fetch(Accessor& acc, int n) {
    const auto step = [n](int bit) {
      return ((n >> bit) & 1) * static_cast<openvdb::Int32>(Leaf::DIM);
    };
    const openvdb::Coord q = origin_.offsetBy(step(2), step(1), step(0));
    const Leaf* leaf = acc.probeConstLeaf(q);
    leaf_[n] = leaf;
    if (leaf != nullptr) {
      values_[n] = leaf->buffer().data();  // (once: data() checks for out-of-core data)
      mask_[n] = Leaf::SIZE - 1;
    } else {
      constant_[n] = acc.getValue(q);
      active_[n] = acc.isValueOn(q);
      values_[n] = &constant_[n];
      mask_[n] = 0;
    }
    fetched_ |= 1u << n;
  }

  // acc.isValueOn(voxel), for a voxel of the neighbourhood.
  bool active(Accessor& acc, const openvdb::Coord& voxel) {
    const int n = neighbour(acc, voxel);
    if (n < 0) return acc.isValueOn(voxel);
    const Leaf* leaf = leaf_[n];
    return leaf != nullptr ? leaf->valueMask().isOn(Leaf::coordToOffset(voxel)) : active_[n];
  }

  ValueT value(Accessor& acc, const openvdb::Coord& voxel) {
    const int n = neighbour(acc, voxel);
    if (n < 0) return acc.getValue(voxel);
    return values_[n][Leaf::coordToOffset(voxel) & mask_[n]];
  }

  // No leaf's origin (origins are multiples of Leaf::DIM): the first sample anchors.
  openvdb::Coord origin_{1, 1, 1};
  unsigned fetched_ = 0;
  const Leaf* leaf_[8] = {};
  const ValueT* values_[8] = {};
  openvdb::Index mask_[8] = {};
  ValueT constant_[8] = {};
  bool active_[8] = {};
};

/// The sampler tag of LeafNeighbourhood: BoxSampler's results.
struct LeafBoxSampler {};

}  // namespace

/// The grids, their precision hidden behind one virtual call per accumulate().
struct VectorField::Impl {
  using Frames = VectorField::Frames;
  virtual ~Impl() = default;
  /// Adds the module's contribution (mode and scale applied) for `rows` to `out`, sampling
  /// between `frames`.
  virtual void accumulate(const VectorField::Settings& s, const Frames& frames,
                          const ForceInput& in, RowRange rows, Vec3Rows& out) const = 0;
  /// The field at `world` between `frames`, after the outside policy, before scale.
  virtual Eigen::Vector3f sample(const VectorField::Settings& s, const Frames& frames,
                                 const Eigen::Vector3d& world) const = 0;
  /// dead[row] = 1 for the rows of `rows` outside the active voxels of frames.first (the frame
  /// at or before the instant).
  virtual void flagOutside(const Frames& frames, const ForceInput& in, RowRange rows,
                           std::uint8_t* dead) const = 0;
  /// VectorField::sampleBlocks().
  virtual void sampleBlocks(const Vec3View& position, RowRange rows, BlockCoord* out) const = 0;
  std::string valueType;
  bool staggered = false;
  int frameCount = 1;
  double voxelSize = 0.0;
  double maxMagnitude = 0.0;
};

namespace {

// Rows ahead whose corners add() asks for.
constexpr Eigen::Index kPrefetchRows = 8;

template <class GridT>
struct ImplT final : VectorField::Impl {
  using ValueT = typename GridT::ValueType;
  // Unregistered: the grids never change after loading, and registering an accessor with the tree
  // locks a shared table at every construction (once per tile and pass).
  using Accessor = typename GridT::ConstUnsafeAccessor;
  std::vector<typename GridT::ConstPtr> grids;

  // One frame: a grid's accessor (built per call) and its transform. The maps baked and written
  // by most tools (a uniform voxel size, with or without an offset) are final classes: calling
  // them directly lets the compiler inline world → index, which a virtual call through the
  // Transform would not. The arithmetic is the map's own, so the bits are the same.
  struct Frame {
    Frame(const GridT& grid)
        : acc(grid.getConstUnsafeAccessor()),
          xform(&grid.transform()),
          scale(xform->template constMap<openvdb::math::UniformScaleMap>().get()),
          scaleTranslate(
              xform->template constMap<openvdb::math::UniformScaleTranslateMap>().get()) {}
    Accessor acc;
    LeafNeighbourhood<GridT> cells;  // LeafBoxSampler's
    const openvdb::math::Transform* xform;
    const openvdb::math::UniformScaleMap* scale;
    const openvdb::math::UniformScaleTranslateMap* scaleTranslate;

    openvdb::Vec3d toIndex(const openvdb::Vec3d& world) const {
      if (scale != nullptr) return scale->applyInverseMap(world);
      if (scaleTranslate != nullptr) return scaleTranslate->applyInverseMap(world);
      return xform->worldToIndex(world);
    }
  };

  template <class Sampler>
  static Eigen::Vector3f at(Frame& f, const openvdb::Vec3d& world, bool zeroOutside) {
    return atIndex<Sampler>(f, f.toIndex(world), zeroOutside);
  }
  // at(), given the frame's index-space position of the world position (f.toIndex(world)).
  template <class Sampler>
  static Eigen::Vector3f atIndex(Frame& f, const openvdb::Vec3d& index, bool zeroOutside) {
    if constexpr (std::is_same_v<Sampler, LeafBoxSampler>) {
      ValueT u;
      if (!f.cells.sample(f.acc, index, zeroOutside, u)) return Eigen::Vector3f::Zero();
      return toFloat(u);
    } else {
      if (zeroOutside && !f.acc.isValueOn(openvdb::Coord::round(index))) {
        return Eigen::Vector3f::Zero();
      }
      ValueT u;
      Sampler::sample(f.acc, index, u);
      return toFloat(u);
    }
  }

  // The two frames' samplers for one call, and the sample at a world position, blended in time.
  template <class Sampler>
  struct Blend {
    Blend(const ImplT& impl, const VectorField::Settings& s, const Frames& at)
        : frames(at),
          first(*impl.grids[frames.first]),
          second(*impl.grids[frames.second]),
          blend(frames.second != frames.first && frames.weight != 0.0f),
          zero(s.outside != VectorField::Outside::Background) {}
    Eigen::Vector3f operator()(const openvdb::Vec3d& world) {
      return (*this)(world, first.toIndex(world));
    }
    // The sample at `world`, given its index in the first frame (first.toIndex(world)).
    Eigen::Vector3f operator()(const openvdb::Vec3d& world, const openvdb::Vec3d& firstIndex) {
      const Eigen::Vector3f u = atIndex<Sampler>(first, firstIndex, zero);
      if (!blend) return u;
      const Eigen::Vector3f u1 = at<Sampler>(second, world, zero);
      const float w = frames.weight, one = 1.0f - w;
      return {one * u.x() + w * u1.x(), one * u.y() + w * u1.y(), one * u.z() + w * u1.z()};
    }
    Frames frames;
    Frame first, second;
    bool blend, zero;
  };

  template <class Sampler>
  void add(const VectorField::Settings& s, const Frames& between, const ForceInput& in,
           RowRange rows, Vec3Rows& out) const {
    Blend<Sampler> field(*this, s, between);
    const bool drag = s.mode == VectorField::Mode::Drag;
    const ConstVec3Rows p = in.position.rows(rows);
    const ConstVec3Rows v = in.velocity.rows(rows);
    const Eigen::Index n = rows.count();
    // float → double is exact; the sample is rounded to float once.
    const auto world = [&p](Eigen::Index j) { return openvdb::Vec3d(p.x[j], p.y[j], p.z[j]); };
    // LeafBoxSampler: the first frame's index of rows j to j + kPrefetchRows - 1, at
    // ahead[row % kPrefetchRows], worked out once: when the row kPrefetchRows ahead is
    // prefetched, and used when it is sampled.
    openvdb::Vec3d ahead[kPrefetchRows];
    if constexpr (std::is_same_v<Sampler, LeafBoxSampler>) {
      for (Eigen::Index k = 0; k < std::min(n, kPrefetchRows); ++k) {
        ahead[k] = field.first.toIndex(world(k));
      }
    }
    for (Eigen::Index j = 0; j < n; ++j) {
      Eigen::Vector3f u;
      if constexpr (std::is_same_v<Sampler, LeafBoxSampler>) {
        openvdb::Vec3d& slot = ahead[static_cast<std::size_t>(j) % kPrefetchRows];
        const openvdb::Vec3d index = slot;
        if (j + kPrefetchRows < n) {
          const openvdb::Vec3d later = field.first.toIndex(world(j + kPrefetchRows));
          slot = later;
          field.first.cells.prefetch(later);
        }
        u = field(world(j), index);
      } else {
        u = field(world(j));
      }
      if (drag) {
        out.x[j] += s.scale * (u.x() - v.x[j]);
        out.y[j] += s.scale * (u.y() - v.y[j]);
        out.z[j] += s.scale * (u.z() - v.z[j]);
      } else {  // Force adds acceleration, Advect velocity
        out.x[j] += s.scale * u.x();
        out.y[j] += s.scale * u.y();
        out.z[j] += s.scale * u.z();
      }
    }
  }

  // Calls f(Sampler{}) with the sampler the grid class and the interpolation ask for.
  template <class F>
  decltype(auto) withSampler(const VectorField::Settings& s, F&& f) const {
    namespace vt = openvdb::tools;
    const bool quadratic = s.interpolation == VectorField::Interpolation::Quadratic;
    if (staggered) {
      return quadratic ? f(vt::StaggeredQuadraticSampler{}) : f(vt::StaggeredBoxSampler{});
    }
    return quadratic ? f(vt::QuadraticSampler{}) : f(LeafBoxSampler{});
  }

  void accumulate(const VectorField::Settings& s, const Frames& between, const ForceInput& in,
                  RowRange rows, Vec3Rows& out) const override {
    withSampler(s, [&](auto sampler) { add<decltype(sampler)>(s, between, in, rows, out); });
  }

  Eigen::Vector3f sample(const VectorField::Settings& s, const Frames& between,
                         const Eigen::Vector3d& world) const override {
    return withSampler(s, [&](auto sampler) {
      Blend<decltype(sampler)> field(*this, s, between);
      return field(openvdb::Vec3d(world.x(), world.y(), world.z()));
    });
  }

  void flagOutside(const Frames& between, const ForceInput& in, RowRange rows,
                   std::uint8_t* dead) const override {
    Frame first(*grids[between.first]);
    const ConstVec3Rows p = in.position.rows(rows);
    for (Eigen::Index j = 0; j < rows.count(); ++j) {
      const openvdb::Vec3d index = first.toIndex(openvdb::Vec3d(p.x[j], p.y[j], p.z[j]));
      if (!first.acc.isValueOn(openvdb::Coord::round(index))) {
        dead[rows.begin + static_cast<std::size_t>(j)] = 1;
      }
    }
  }

  void sampleBlocks(const Vec3View& position, RowRange rows, BlockCoord* out) const override {
    using Leaf = typename GridT::TreeType::LeafNodeType;
    // Beyond ±2^30 voxels (or not finite) floor() would not fit an int.
    constexpr double kFar = 1073741824.0;
    const Frame first(*grids.front());
    const ConstVec3Rows p = position.rows(rows);
    for (Eigen::Index j = 0; j < rows.count(); ++j) {
      const openvdb::Vec3d index = first.toIndex(openvdb::Vec3d(p.x[j], p.y[j], p.z[j]));
      BlockCoord& b = out[j];
      if (!(std::abs(index.x()) < kFar && std::abs(index.y()) < kFar &&
            std::abs(index.z()) < kFar)) {
        b = BlockCoord{BlockCoord::kNowhere, 0, 0};
        continue;
      }
      const openvdb::Vec3i base = openvdb::tools::local_util::floorVec3(index);
      b = BlockCoord{base.x() >> Leaf::LOG2DIM, base.y() >> Leaf::LOG2DIM,
                     base.z() >> Leaf::LOG2DIM};
    }
  }
};

template <class GridT>
std::unique_ptr<VectorField::Impl> load(const VectorField::Settings& s,
                                        std::vector<openvdb::GridBase::Ptr>& raw,
                                        const char* typeName) {
  auto impl = std::make_unique<ImplT<GridT>>();
  impl->valueType = typeName;
  impl->staggered = raw.front()->getGridClass() == openvdb::GRID_STAGGERED;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    auto grid = openvdb::gridPtrCast<GridT>(raw[i]);
    const std::string path = framePath(s, s.firstFrame + static_cast<int>(i));
    if (!grid) {
      throw std::runtime_error(vdbGridLabel(path, s.grid) + ": holds " + raw[i]->valueType() +
                               " values, unlike the first frame (" + typeName + ")");
    }
    if ((grid->getGridClass() == openvdb::GRID_STAGGERED) != impl->staggered) {
      throw std::runtime_error(vdbGridLabel(path, s.grid) +
                               ": staggered or not, unlike the first frame");
    }
    impl->grids.push_back(grid);
  }
  impl->frameCount = static_cast<int>(raw.size());
  const openvdb::Vec3d voxel = impl->grids.front()->voxelSize();
  impl->voxelSize = std::min({voxel.x(), voxel.y(), voxel.z()});
  for (const auto& grid : impl->grids) {
    for (auto it = grid->cbeginValueOn(); it; ++it) {
      impl->maxMagnitude = std::max(impl->maxMagnitude, static_cast<double>(it->length()));
    }
  }
  return impl;
}

}  // namespace

namespace {

std::unique_ptr<const VectorField::Impl> makeImpl(const VectorField::Settings& s,
                                                  std::vector<openvdb::GridBase::Ptr> raw) {
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const std::string path = framePath(s, s.firstFrame + static_cast<int>(i));
    const auto& grid = raw[i];
    if (!grid) throw std::runtime_error(vdbGridLabel(path, s.grid) + ": no grid");
    if (!grid->isType<openvdb::Vec3fGrid>() && !grid->isType<openvdb::Vec3dGrid>()) {
      throw std::runtime_error(vdbGridLabel(path, s.grid) + ": holds " + grid->valueType() +
                               " values (" + grid->type() +
                               "); a vector field needs vec3s or vec3d");
    }
  }
  if (raw.front()->isType<openvdb::Vec3fGrid>()) return load<openvdb::Vec3fGrid>(s, raw, "vec3s");
  return load<openvdb::Vec3dGrid>(s, raw, "vec3d");
}

int frameSpan(const VectorField::Settings& s) {
  if (s.fps != 0.0 && !(s.fps >= 1e-6 && s.fps <= 1e6)) {
    throw std::invalid_argument(s.file + ": a field sequence's fps must be from 1e-6 to 1e6");
  }
  if (s.fps > 0.0 && s.lastFrame < s.firstFrame) {
    throw std::invalid_argument(s.file + ": a field sequence needs lastFrame >= firstFrame");
  }
  return s.fps > 0.0 ? s.lastFrame - s.firstFrame + 1 : 1;
}

// fps as numerator / 2^shift exactly (exact::dyadic); 1e-6 <= fps <= 1e6 keeps the shift below 73.
std::pair<unsigned __int128, int> exactFps(double fps) {
  if (!(fps > 0.0)) return {0, 0};
  const exact::Dyadic d = exact::dyadic(fps);
  return {d.numerator, d.shift};
}

}  // namespace

VectorField::Frames VectorField::framesAt(const TickInstant& at) const {
  Frames f;
  const auto count = static_cast<std::size_t>(frameCount());
  if (count < 2) return f;
  // t·fps = (2·tick + halves) · numerator / (2·H · 2^shift): below 2^105 over below 2^94.
  using u128 = unsigned __int128;
  const u128 num = static_cast<u128>(2 * at.tick + at.halves) * fpsNumerator_;
  const u128 den = static_cast<u128>(2 * at.stepRateHz) << fpsShift_;
  const u128 base = num / den;
  if (base >= count - 1) {
    f.first = f.second = count - 1;
  } else {
    f.first = static_cast<std::size_t>(base);
    f.second = f.first + 1;
    f.weight = exact::fractionToFloat(num % den, den);
  }
  return f;
}

namespace {

VectorField::Frames framesAtSeconds(const VectorField& field, double t) {
  VectorField::Frames f;
  const auto count = static_cast<std::size_t>(field.frameCount());
  if (count < 2) return f;
  const double x = t * field.settings().fps;
  if (x >= static_cast<double>(count - 1)) {
    f.first = f.second = count - 1;
  } else if (x > 0.0) {
    const double base = std::floor(x);
    f.first = static_cast<std::size_t>(base);
    f.second = f.first + 1;
    f.weight = static_cast<float>(x - base);
  }
  return f;
}

}  // namespace

VectorField::VectorField(const Settings& settings) : s_(settings) {
  const int frames = frameSpan(s_);
  std::tie(fpsNumerator_, fpsShift_) = exactFps(s_.fps);
  if (s_.fps > 0.0 && s_.file.find("{frame}") == std::string::npos) {
    throw std::invalid_argument(s_.file + ": a field sequence needs {frame} in the file name");
  }
  std::vector<openvdb::GridBase::Ptr> raw;
  for (int f = s_.firstFrame; f < s_.firstFrame + frames; ++f) {
    raw.push_back(readVdbGrid(framePath(s_, f), s_.grid));
  }
  impl_ = makeImpl(s_, std::move(raw));
}

VectorField::VectorField(const Settings& settings, const Grids& grids) : s_(settings) {
  const int frames = frameSpan(s_);
  std::tie(fpsNumerator_, fpsShift_) = exactFps(s_.fps);
  if (grids.grids.size() != static_cast<std::size_t>(frames)) {
    throw std::invalid_argument(s_.file + ": " + std::to_string(grids.grids.size()) +
                                " grids given for " + std::to_string(frames) + " frames");
  }
  impl_ = makeImpl(s_, grids.grids);
}

VectorField::~VectorField() = default;

void VectorField::accumulate(const ForceInput& in, RowRange rows, Vec3Rows& acceleration) const {
  if (s_.mode == Mode::Advect) return;  // prescribes velocity: ForceSet never asks
  impl_->accumulate(s_, framesAt(in.at), in, rows, acceleration);
}

void VectorField::accumulateVelocity(const ForceInput& in, RowRange rows,
                                     Vec3Rows& velocity) const {
  if (s_.mode != Mode::Advect) return;
  impl_->accumulate(s_, framesAt(in.at), in, rows, velocity);
}

void VectorField::endTick(ParticlePool& pool, const TickInstant& end) {
  if (s_.outside != Outside::Kill) return;
  const ForceInput in{pool, Vec3View::of(pool.position()), Vec3View::of(pool.velocity()), end};
  std::uint8_t* dead = pool.dead().data();
  parallelForRows(pool.size(), [&](std::size_t b, std::size_t e) {
    flagOutside(in, RowRange{b, e}, dead);
  });
}

Eigen::Vector3f VectorField::sample(const Eigen::Vector3f& x, double t) const {
  return impl_->sample(s_, framesAtSeconds(*this, t), x.cast<double>());
}

bool VectorField::sampleBlocks(const Vec3View& position, RowRange rows, BlockCoord* out) const {
  impl_->sampleBlocks(position, rows, out);
  return true;
}

void VectorField::flagOutside(const ForceInput& in, RowRange rows, std::uint8_t* dead) const {
  impl_->flagOutside(framesAt(in.at), in, rows, dead);
}

const std::string& VectorField::valueType() const { return impl_->valueType; }
bool VectorField::staggered() const { return impl_->staggered; }
int VectorField::frameCount() const { return impl_->frameCount; }
double VectorField::voxelSize() const { return impl_->voxelSize; }
double VectorField::maxMagnitude() const { return impl_->maxMagnitude; }

}  // namespace tickfx
