#include "io/cache/VdbPointCache.h"

#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "fields/vdb/RegisteredGrid.h"
#include "fields/vdb/VdbGridFile.h"
#include "io/cache/AttributeGroups.h"
#include "io/cache/VdbPointCacheBytes.h"
#include "io/cache/VdbPointGrouping.h"
#include "io/cache/VdbPointsEncoder.h"
#include "io/util/AtomicFile.h"
#include "io/util/Fingerprint.h"
#include "io/util/ProfiledTbb.h"

namespace tickfx::io {
namespace {

namespace vdbp = openvdb::points;

const std::string kGridName = "points";

const char* const kMetaEffectHash = "tickfx_effect_hash";
const char* const kMetaSeed = "tickfx_seed";
const char* const kMetaStepRate = "tickfx_step_rate";
const char* const kMetaIntegrator = "tickfx_integrator";
const char* const kMetaFrame = "tickfx_frame";
const char* const kMetaTime = "tickfx_time";
const char* const kMetaVersion = "tickfx_version";
const char* const kMetaPointCount = "tickfx_point_count";

using PositionArray = vdbp::TypedAttributeArray<openvdb::Vec3f, vdbp::NullCodec>;
using QuantisedPositionArray =
    vdbp::TypedAttributeArray<openvdb::Vec3f, vdbp::FixedPointCodec<false, vdbp::PositionRange>>;
using VectorArray = vdbp::TypedAttributeArray<openvdb::Vec3f, vdbp::NullCodec>;
using IdArray = vdbp::TypedAttributeArray<std::int64_t, vdbp::NullCodec>;
using FloatArray = vdbp::TypedAttributeArray<float, vdbp::NullCodec>;
using IntArray = vdbp::TypedAttributeArray<std::int32_t, vdbp::NullCodec>;

std::string where(const std::string& path) { return vdbGridLabel(path, kGridName); }

// ---- writing ---------------------------------------------------------------------------------

// The attributes every cache has, in the order they are written; custom ones follow.
const std::vector<std::string>& standardAttributes() {
  static const std::vector<std::string> names = {"P", "v", "id", "age", "life", "mass"};
  return names;
}

bool isStandard(const std::string& name) {
  const std::vector<std::string>& names = standardAttributes();
  return std::find(names.begin(), names.end(), name) != names.end();
}

void checkAttributeName(const std::string& name) {
  if (isStandard(name)) {
    throw std::invalid_argument("custom attribute '" + name +
                                "' has the name of a standard attribute of a VDB points cache");
  }
  if (!vdbp::AttributeSet::Descriptor::validName(name)) {
    throw std::invalid_argument("custom attribute '" + name +
                                "' is not a valid OpenVDB attribute name (letters, digits, '_', "
                                "'|' and ':')");
  }
}

void checkColumns(const FrameData& frame) {
  const auto rows = static_cast<Eigen::Index>(frame.size());
  auto sized = [&](const FloatColumn& c) { return c.size() == rows; };
  bool ok = sized(frame.age) && sized(frame.life) && sized(frame.mass) &&
            frame.attributes.size() == frame.attributeNames.size();
  for (int c = 0; c < 3; ++c) ok = ok && sized(frame.position[c]) && sized(frame.velocity[c]);
  for (const FloatColumn& a : frame.attributes) ok = ok && sized(a);
  if (!ok) throw std::invalid_argument("frame columns of different lengths");
  for (const AttributeGroup& g : attributeGroups(frame.attributeNames)) checkAttributeName(g.name);
}

using Leaf = vdbp::PointDataTree::LeafNodeType;

// What an attribute of the grid holds, in the descriptor's order: P, v, id, age, life, mass, then
// the frame's attribute groups as Houdini's typed attributes (hitnum an int32, hitpos a vec3s).
// `column`: the GroupedPoints::columns it reads, of one float a row; a vector reads a column of
// rows of three (the velocity) or the three columns from `column` on.
struct GridAttribute {
  enum class Kind { Position, Vector, Id, Float, Int };
  std::string name;
  Kind kind = Kind::Float;
  std::size_t column = 0;
};

// The grid's attributes of a frame with these attribute columns.
std::vector<GridAttribute> gridAttributes(const std::vector<std::string>& attributeNames) {
  using Kind = GridAttribute::Kind;
  const std::vector<std::string>& standard = standardAttributes();  // P, v, id, age, life, mass
  std::vector<GridAttribute> attributes = {{standard[0], Kind::Position, 0},
                                           {standard[1], Kind::Vector, kVelocityColumn},
                                           {standard[2], Kind::Id, 0},
                                           {standard[3], Kind::Float, kAgeColumn},
                                           {standard[4], Kind::Float, kLifeColumn},
                                           {standard[5], Kind::Float, kMassColumn}};
  for (const AttributeGroup& g : attributeGroups(attributeNames)) {
    const Kind kind = g.kind == AttributeKind::Vec3  ? Kind::Vector
                      : g.kind == AttributeKind::Int ? Kind::Int
                                                     : Kind::Float;
    attributes.push_back({g.name, kind, kStandardFloatColumns + g.column});
  }
  return attributes;
}

// The x, y and z of vector attribute `a`: lane j of row r at lanes[j][r * stride[j]], from a
// column of rows of three (strides 3) or three columns of one float a row (stride 1, or 0 for a
// column whose rows all hold one value).
struct VectorLanes {
  std::array<const float*, 3> lanes;
  std::array<std::size_t, 3> stride;
};
VectorLanes vectorLanes(const GroupedPoints& points, const GridAttribute& a) {
  const GroupedPoints::Column& first = points.columns[a.column];
  const float* const x = first.values.get();
  if (first.width == 3) return {{x, x + 1, x + 2}, {3, 3, 3}};
  VectorLanes v;
  for (std::size_t j = 0; j < 3; ++j) {
    v.lanes[j] = points.columns[a.column + j].values.get();
    v.stride[j] = points.columns[a.column + j].width;
  }
  return v;
}

// Calls f(std::type_identity<Array>()) with the array type of attributes of `kind`.
template <typename PositionArray, typename F>
void withArrayType(GridAttribute::Kind kind, const F& f) {
  using Kind = GridAttribute::Kind;
  switch (kind) {
    case Kind::Position:
      return f(std::type_identity<PositionArray>());
    case Kind::Vector:
      return f(std::type_identity<VectorArray>());
    case Kind::Id:
      return f(std::type_identity<IdArray>());
    case Kind::Int:
      return f(std::type_identity<IntArray>());
    case Kind::Float:
      return f(std::type_identity<FloatArray>());
  }
}

// The grid's descriptor: each attribute's name and its array's type, P first.
template <typename PositionArray>
vdbp::AttributeSet::Descriptor::Ptr gridDescriptor(const std::vector<GridAttribute>& attributes) {
  auto descriptor = vdbp::AttributeSet::Descriptor::create(PositionArray::attributeType());
  for (std::size_t a = 1; a < attributes.size(); ++a) {
    withArrayType<PositionArray>(
        attributes[a].kind, [&]<typename Array>(std::type_identity<Array>) {
          descriptor = descriptor->duplicateAppend(attributes[a].name, Array::attributeType());
        });
  }
  return descriptor;
}

// Leaf l with its voxel values, and its default attribute set.
std::unique_ptr<Leaf> makeEmptyLeaf(const GroupedPoints& points, std::size_t l) {
  auto leaf = std::make_unique<Leaf>(points.leaves.origins[l]);
  std::memcpy(leaf->buffer().data(), points.leaves.voxelEnds.get() + l * Leaf::SIZE,
              Leaf::SIZE * sizeof(openvdb::PointDataIndex32));
  leaf->setValueMask(points.leaves.masks[l]);
  return leaf;
}

// Gives `leaf` an attribute set of its point count, each array uniform: arrays to be expanded
// and filled.
void addUniformArrays(Leaf& leaf, const vdbp::AttributeSet::Descriptor::Ptr& descriptor) {
  // (initializeAttributes takes a descriptor of P alone; this one has every attribute.)
  leaf.replaceAttributeSet(
      new vdbp::AttributeSet(descriptor, static_cast<openvdb::Index>(leaf.pointCount())),
      /*allowMismatchingDescriptors=*/true);
}

// Calls set(k, value) for each point k of leaf l in its array's order, with the value attribute
// `a` holds for it.
template <typename Set>
void eachValue(const GroupedPoints& points, std::size_t l, const GridAttribute& a, const Set& set) {
  using Kind = GridAttribute::Kind;
  const std::size_t begin = points.leafPoints(l).first;
  const std::size_t count = points.leafPoints(l).second - begin;
  const float* const column = points.columns[a.column].values.get();  // (Float, Int)
  const std::size_t width = points.columns[a.column].width;           // (Float, Int: 1, or 0)
  const auto row = [&](std::size_t k) { return points.row(begin + k); };
  switch (a.kind) {
    case Kind::Position: {
      const openvdb::Vec3f* offset = points.offset.get();
      for (std::size_t k = 0; k < count; ++k) set(k, offset[row(k)]);
      return;
    }
    case Kind::Vector: {
      const auto [lanes, stride] = vectorLanes(points, a);
      for (std::size_t k = 0; k < count; ++k) {
        const std::size_t r = row(k);
        set(k, openvdb::Vec3f(lanes[0][r * stride[0]], lanes[1][r * stride[1]],
                              lanes[2][r * stride[2]]));
      }
      return;
    }
    case Kind::Id: {
      const std::uint64_t* id = points.id.get();
      for (std::size_t k = 0; k < count; ++k) set(k, static_cast<std::int64_t>(id[row(k)]));
      return;
    }
    case Kind::Int: {
      const float* x = column;
      for (std::size_t k = 0; k < count; ++k) set(k, static_cast<std::int32_t>(x[row(k) * width]));
      return;
    }
    case Kind::Float: {
      const float* x = column;
      for (std::size_t k = 0; k < count; ++k) set(k, x[row(k) * width]);
      return;
    }
  }
}

// The array at `pos` of `leaf` as its own type, expanded to one value a point (each is then
// set: no fill). Typed access calls the codec inline, where a handle calls through a pointer.
template <typename Array>
Array& expandedArray(Leaf& leaf, std::size_t pos) {
  auto& array = static_cast<Array&>(leaf.attributeArray(pos));
  array.expand(/*fill=*/false);
  return array;
}

// Leaf l of `points`, every attribute filled through its array: what OpenVDB's own writer
// takes, the reference that the bytes GroupedValues stores are held to.
template <typename PositionArray>
std::unique_ptr<Leaf> makeLeaf(const std::vector<GridAttribute>& attributes,
                               const GroupedPoints& points, std::size_t l,
                               const vdbp::AttributeSet::Descriptor::Ptr& descriptor) {
  std::unique_ptr<Leaf> leaf = makeEmptyLeaf(points, l);
  addUniformArrays(*leaf, descriptor);
  for (std::size_t pos = 0; pos < attributes.size(); ++pos) {
    const auto fill = [&]<typename Array>(Array& array) {
      eachValue(points, l, attributes[pos], [&](std::size_t k, const auto& value) {
        if constexpr (std::is_convertible_v<decltype(value), typename Array::ValueType>)
          array.setUnsafe(static_cast<openvdb::Index>(k), value);
        else
          throw std::logic_error("VDB points: an attribute's values are not of its array's type");
      });
    };
    withArrayType<PositionArray>(
        attributes[pos].kind,
        [&]<typename Array>(std::type_identity<Array>) { fill(expandedArray<Array>(*leaf, pos)); });
  }
  return leaf;
}

// The grid's values, from the grouped points straight into the file's bytes: each encoded by its
// array's codec and stored as the array would store it.
template <typename PositionArray>
class GroupedValues final : public PointValues {
 public:
  GroupedValues(GroupedPoints& points, std::vector<GridAttribute> attributes)
      : points_(points), attributes_(std::move(attributes)) {}

  void store(std::size_t attribute, const openvdb::Coord& origin, std::size_t count,
             char* to) const override {
    std::size_t& next = next_.local();
    const std::size_t l = leafAt(origin, next);
    const auto [begin, end] = points_.leafPoints(l);
    if (end - begin != count || attribute >= attributes_.size())
      throw std::logic_error("VDB points: values asked for a leaf the frame does not have");
    next = l + 1;
    const GridAttribute& a = attributes_[attribute];
    withArrayType<PositionArray>(
        a.kind, [&]<typename Array>(std::type_identity<Array>) { storeAs<Array>(l, a, to); });
  }

 private:
  // The index of the leaf at `origin`, tried first at `guess`.
  std::size_t leafAt(const openvdb::Coord& origin, std::size_t guess) const {
    const auto& origins = points_.leaves.origins;
    if (guess < origins.size() && origins[guess] == origin) return guess;
    const auto leaf = std::lower_bound(origins.begin(), origins.end(), origin);
    if (leaf == origins.end() || *leaf != origin)
      throw std::logic_error("VDB points: values asked for a leaf the frame does not have");
    return static_cast<std::size_t>(leaf - origins.begin());
  }

  template <typename Array>
  void storeAs(std::size_t l, const GridAttribute& a, char* to) const {
    using Storage = typename Array::StorageType;
    if constexpr (std::is_same_v<typename Array::Codec, vdbp::NullCodec>) {
      storePlain(l, a, to);
    } else {
      // Encoded into a buffer in cache and copied into `to` a run at a time: the 16-bit
      // positions' 6-byte values stored one by one into the chunk, whose lines are not in cache
      // yet, filled the store buffer (6.5 ms of the threads a frame of 10⁶ against 3.5). `to` by
      // value: a captured reference would be reloaded after every store through it.
      constexpr std::size_t kRun = 256;
      const auto [begin, end] = points_.leafPoints(l);
      const std::size_t count = end - begin;
      std::array<Storage, kRun> run;
      eachValue(points_, l, a, [&run, to, count](std::size_t k, const auto& value) {
        if constexpr (std::is_convertible_v<decltype(value), typename Array::ValueType>) {
          Array::Codec::encode(typename Array::ValueType(value), run[k % kRun]);
          if (k % kRun == kRun - 1 || k + 1 == count) {
            const std::size_t first = k - k % kRun;
            std::memcpy(to + first * sizeof(Storage), run.data(),
                        (k + 1 - first) * sizeof(Storage));
          }
        } else {
          throw std::logic_error("VDB points: an attribute's values are not of its array's type");
        }
      });
    }
  }

  // Leaf l's values of attribute `a` as an array that stores them as they are (NullCodec) holds
  // them: the same bytes as storeAs()'s general way, but copies of the offsets and, for the
  // others, loops whose stores alias nothing (the general way's stores through `to` may alias
  // anything, so it reloaded its pointers after each value), each value gathered from its row
  // where the rows are not in order.
  void storePlain(std::size_t l, const GridAttribute& a, char* __restrict to) const {
    const std::size_t begin = points_.leafPoints(l).first;
    const std::size_t count = points_.leafPoints(l).second - begin;
    if (points_.source) {
      storeRows(a, count, to, [rows = points_.source.get() + begin](std::size_t k) {
        return std::size_t{rows[k]};
      });
    } else {
      storeRows(a, count, to, [begin](std::size_t k) { return begin + k; });
    }
  }

  // The values of attribute `a` at rows row(0), … row(count − 1), at `to`.
  template <typename Row>
  void storeRows(const GridAttribute& a, std::size_t count, char* __restrict to,
                 const Row& row) const {
    using Kind = GridAttribute::Kind;
    const float* const column = points_.columns[a.column].values.get();  // (Float, Int)
    const std::size_t width = points_.columns[a.column].width;           // (Float, Int: 1, or 0)
    constexpr std::size_t kFloat = sizeof(float);
    switch (a.kind) {
      case Kind::Position: {  // the offsets, as openvdb::Vec3f's three floats
        static_assert(sizeof(openvdb::Vec3f) == 3 * sizeof(float));
        const openvdb::Vec3f* const __restrict offset = points_.offset.get();
        for (std::size_t k = 0; k < count; ++k)
          std::memcpy(to + k * sizeof(openvdb::Vec3f), offset + row(k), sizeof(openvdb::Vec3f));
        return;
      }
      case Kind::Id: {  // std::uint64_t to std::int64_t keeps the bits
        const std::uint64_t* const __restrict id = points_.id.get();
        for (std::size_t k = 0; k < count; ++k)
          std::memcpy(to + k * sizeof(std::uint64_t), id + row(k), sizeof(std::uint64_t));
        return;
      }
      case Kind::Float: {
        const float* const __restrict x = column;
        if (width == 0) {  // the one value, for every point
          for (std::size_t k = 0; k < count; ++k) std::memcpy(to + k * kFloat, x, kFloat);
          return;
        }
        for (std::size_t k = 0; k < count; ++k) std::memcpy(to + k * kFloat, x + row(k), kFloat);
        return;
      }
      case Kind::Vector: {
        const VectorLanes v = vectorLanes(points_, a);
        if (v.stride[0] == 3) {  // rows of three, as the array holds them
          const float* const __restrict xyz = v.lanes[0];
          for (std::size_t k = 0; k < count; ++k)
            std::memcpy(to + k * 3 * kFloat, xyz + row(k) * 3, 3 * kFloat);
          return;
        }
        const float* const __restrict x = v.lanes[0], * const __restrict y = v.lanes[1], * const __restrict z = v.lanes[2];
        const auto [sx, sy, sz] = v.stride;
        for (std::size_t k = 0; k < count; ++k, to += 3 * kFloat) {
          const std::size_t r = row(k);
          std::memcpy(to, x + r * sx, kFloat);
          std::memcpy(to + kFloat, y + r * sy, kFloat);
          std::memcpy(to + 2 * kFloat, z + r * sz, kFloat);
        }
        return;
      }
      case Kind::Int: {
        const float* const __restrict x = column;
        for (std::size_t k = 0; k < count; ++k) {
          const auto v = static_cast<std::int32_t>(x[row(k) * width]);
          std::memcpy(to + sizeof v * k, &v, sizeof v);
        }
        return;
      }
    }
  }

  GroupedPoints& points_;
  std::vector<GridAttribute> attributes_;
  // A thread's own: the leaf after the last it stored (the encoder asks for leaves in the tree's
  // order, which is nearly always the leaves' Coord order).
  mutable tbb::enumerable_thread_specific<std::size_t> next_;
};

// The frame's points grouped as the grid's position array places them.
template <typename PositionArray>
GroupedPoints groupedPoints(const FrameData& frame, Grouping grouping) {
  constexpr bool kQuantised = !std::is_same_v<typename PositionArray::Codec, vdbp::NullCodec>;
  return groupPoints<kQuantised>(frame, grouping);
}

// A leaf of one point whose arrays are those of `descriptor`, each uniform: PointLeaves::sample.
std::unique_ptr<Leaf> sampleLeaf(const vdbp::AttributeSet::Descriptor::Ptr& descriptor) {
  auto leaf = std::make_unique<Leaf>(openvdb::Coord(0));
  leaf->replaceAttributeSet(new vdbp::AttributeSet(descriptor, 1),
                            /*allowMismatchingDescriptors=*/true);
  return leaf;
}

// The grid of no leaf with the frame's metadata, from OpenVDB's registry
// (fields/vdb/RegisteredGrid.h says why).
vdbp::PointDataGrid::Ptr emptyGrid(const FrameData& frame, const VdbCacheMetadata& meta) {
  auto grid = newRegisteredGrid<vdbp::PointDataGrid>();
  grid->setName(kGridName);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
  grid->insertMeta(kMetaEffectHash, openvdb::StringMetadata(meta.effectHash));
  grid->insertMeta(kMetaSeed, openvdb::Int64Metadata(static_cast<std::int64_t>(meta.seed)));
  grid->insertMeta(kMetaStepRate, openvdb::Int64Metadata(meta.stepRateHz));
  grid->insertMeta(kMetaIntegrator, openvdb::StringMetadata(meta.integrator));
  grid->insertMeta(kMetaFrame, openvdb::Int64Metadata(frame.frame));
  grid->insertMeta(kMetaTime, openvdb::DoubleMetadata(frame.timeSeconds));
  grid->insertMeta(kMetaVersion, openvdb::StringMetadata(meta.tickfxVersion));
  grid->insertMeta(kMetaPointCount,
                   openvdb::Int64Metadata(static_cast<std::int64_t>(frame.size())));
  return grid;
}

// The grid of `points` with the frame's metadata, each leaf made by makeLeaf(l). Leaves are
// independent: made in parallel (as OpenVDB's point conversion does), then handed to the tree in
// order.
template <typename MakeLeaf>
vdbp::PointDataGrid::Ptr makeGrid(const GroupedPoints& points, const MakeLeaf& makeLeaf,
                                  const FrameData& frame, const VdbCacheMetadata& meta) {
  std::vector<std::unique_ptr<Leaf>> leaves(points.leaves.size());
  par::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t l = range.begin(); l < range.end(); ++l)
                        leaves[l] = makeLeaf(l);
                    });
  vdbp::PointDataGrid::Ptr grid = emptyGrid(frame, meta);
  for (std::unique_ptr<Leaf>& leaf : leaves) grid->tree().addLeaf(leaf.release());
  return grid;
}

std::uint32_t compressionFlags(const VdbCacheOptions& options);

// The file, but for the UUID, handed to use(file) while what it is made from lives: the leaves
// are described to the encoder (PointLeaves), not made, and the values go from the grouped points
// straight into the bytes (encodePointsFile's PointValues) as the file is written
// (EncodedPointsFile).
template <typename PositionArray, typename Use>
void encodeFrame(const FrameData& frame, const VdbCacheMetadata& meta,
                 const VdbCacheOptions& options, Grouping grouping, const Use& use) {
  GroupedPoints points = groupedPoints<PositionArray>(frame, grouping);
  std::vector<GridAttribute> attributes = gridAttributes(frame.attributeNames);
  points.leaves.sample = sampleLeaf(gridDescriptor<PositionArray>(attributes));
  const vdbp::PointDataGrid::Ptr grid = emptyGrid(frame, meta);
  const GroupedValues<PositionArray> values(points, std::move(attributes));
  EncodedPointsFile file =
      encodePointsFile(*grid, points.leaves, compressionFlags(options), values);
  use(file);
}

// The grid with every array filled, as OpenVDB's own writer takes it.
template <typename PositionArray>
vdbp::PointDataGrid::Ptr filledGrid(const FrameData& frame, const VdbCacheMetadata& meta,
                                    Grouping grouping) {
  GroupedPoints points = groupedPoints<PositionArray>(frame, grouping);
  const std::vector<GridAttribute> attributes = gridAttributes(frame.attributeNames);
  const auto descriptor = gridDescriptor<PositionArray>(attributes);
  return makeGrid(
      points,
      [&](std::size_t l) { return makeLeaf<PositionArray>(attributes, points, l, descriptor); },
      frame, meta);
}

template <typename Use>
void encodeFrame(const FrameData& frame, const VdbCacheMetadata& meta,
                 const VdbCacheOptions& options, Grouping grouping, const Use& use) {
  checkColumns(frame);
  if (options.positions == VdbCacheOptions::Positions::Fixed16)
    encodeFrame<QuantisedPositionArray>(frame, meta, options, grouping, use);
  else
    encodeFrame<PositionArray>(frame, meta, options, grouping, use);
}

vdbp::PointDataGrid::Ptr filledGrid(const FrameData& frame, const VdbCacheMetadata& meta,
                                    const VdbCacheOptions& options, Grouping grouping) {
  checkColumns(frame);
  return options.positions == VdbCacheOptions::Positions::Fixed16
             ? filledGrid<QuantisedPositionArray>(frame, meta, grouping)
             : filledGrid<PositionArray>(frame, meta, grouping);
}

// ---- reading ---------------------------------------------------------------------------------

template <typename T>
std::optional<T> metaValue(const openvdb::GridBase& grid, const char* name) {
  using Meta = openvdb::TypedMetadata<T>;
  if (const auto m = grid.getMetadata<Meta>(name)) return m->value();
  return std::nullopt;
}

// True when `transform` maps every index to the same world coordinates, exactly.
bool isIdentity(const openvdb::math::Transform& transform) {
  if (!transform.isLinear()) return false;
  for (const openvdb::Vec3d& x :
       {openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(1, 0, 0), openvdb::Vec3d(0, 1, 0),
        openvdb::Vec3d(0, 0, 1), openvdb::Vec3d(-3, 5, 7)}) {
    if (transform.indexToWorld(x) != x) return false;
  }
  return true;
}

// The file's compression flags (openvdb::io::COMPRESS_*), as io::File would take them.
std::uint32_t compressionFlags(const VdbCacheOptions& options) {
  return options.compression == VdbCacheOptions::Compression::Blosc
             ? openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK
             : openvdb::io::COMPRESS_ACTIVE_MASK;
}

// Room for a whole file (uncompressed): the arrays' bytes, a leaf's offsets and masks (at most
// 2 + 4 KiB), and the headers.
std::size_t expectedFileBytes(const FrameData& frame, const vdbp::PointDataGrid& grid) {
  const std::size_t bytesPerPoint = 12 + 12 + 8 + 4 * (3 + frame.attributes.size());
  return frame.size() * bytesPerPoint + grid.constTree().leafCount() * (6 * 1024) + (64 << 10);
}

// OpenVDB stamps every file with a random UUID (36 characters after the header's version fields),
// so two identical runs would write different bytes. A cache's UUID is made from what the file
// holds instead: the effect's fingerprint, its seed and the frame (an RFC 9562 version-8 UUID).
// The header layout is checked first; a layout this build does not know is left as written.
void stampUuid(std::span<char> bytes, const VdbCacheMetadata& meta, std::int64_t frame) {
  constexpr std::size_t kUuidAt = 21;
  constexpr std::size_t kUuidLength = 36;
  if (bytes.size() < kUuidAt + kUuidLength) return;
  const std::string_view uuid(bytes.data() + kUuidAt, kUuidLength);
  if (std::string_view(bytes.data(), 4) != " BDV" || uuid[8] != '-' || uuid[13] != '-' ||
      uuid[18] != '-' || uuid[23] != '-') {
    return;
  }
  const std::string key =
      meta.effectHash + '/' + std::to_string(meta.seed) + '/' + std::to_string(frame);
  const std::uint64_t hi = fingerprint(key + "/hi"), lo = fingerprint(key + "/lo");
  char text[kUuidLength + 1];
  std::snprintf(text, sizeof text, "%08x-%04x-8%03x-%04x-%012llx", static_cast<unsigned>(hi >> 32),
                static_cast<unsigned>((hi >> 16) & 0xffff), static_cast<unsigned>(hi & 0xfff),
                static_cast<unsigned>(0x8000 | ((lo >> 48) & 0x3fff)),
                static_cast<unsigned long long>(lo & 0xffffffffffffULL));
  std::memcpy(bytes.data() + kUuidAt, text, kUuidLength);
}

// What OpenVDB reads without comparing (readVdbGrid has checked every size it trusts): a leaf's
// voxel offsets must rise to its point count, and every attribute array must hold that many
// points, or the handles below would read past the arrays.
void checkLeaf(const vdbp::PointDataTree::LeafNodeType& leaf, const std::string& file) {
  openvdb::Index32 count = 0;
  for (openvdb::Index n = 0; n < vdbp::PointDataTree::LeafNodeType::SIZE; ++n) {
    const openvdb::Index32 end = leaf.getValue(n);
    if (end < count) {
      throw std::runtime_error(where(file) +
                               ": a leaf's point offsets decrease (the file is corrupt)");
    }
    count = end;
  }
  const vdbp::AttributeSet& set = leaf.attributeSet();
  for (std::size_t i = 0; i < set.size(); ++i) {
    const vdbp::AttributeArray* a = set.getConst(i);
    if (a == nullptr || a->size() != count || (!a->isUniform() && a->dataSize() < a->size())) {
      throw std::runtime_error(where(file) + ": a leaf's attributes do not hold its " +
                               std::to_string(count) + " points (the file is corrupt)");
    }
  }
}

}  // namespace

void writeVdbPointCache(const FrameData& frame, const VdbCacheMetadata& meta,
                        const std::filesystem::path& path, const VdbCacheOptions& options,
                        Durability durability) {
  openvdb::initialize();
  encodeFrame(frame, meta, options, Grouping::Any, [&](EncodedPointsFile& file) {
    stampUuid(std::span<char>(file.head(), file.headSize()), meta, frame.frame);
    writeFileAtomically(
        path, [&](std::ostream& out) { file.write(out); }, durability, file.size());
  });
}

namespace detail {

std::string vdbPointCacheBytes(const FrameData& frame, const VdbCacheMetadata& meta,
                               const VdbCacheOptions& options, VdbEncoder encoder,
                               VdbGrouping grouping) {
  openvdb::initialize();
  const Grouping by = grouping == VdbGrouping::Sorted ? Grouping::Sorted : Grouping::Any;
  std::string bytes;
  if (encoder == VdbEncoder::Parallel) {
    encodeFrame(frame, meta, options, by, [&](const EncodedPointsFile& file) {
      const FileBytes encoded = file.bytes();
      bytes.assign(encoded.data(), encoded.size());
    });
  } else {
    const vdbp::PointDataGrid::Ptr grid = filledGrid(frame, meta, options, by);
    bytes =
        encodePointsFileSerially(grid, compressionFlags(options), expectedFileBytes(frame, *grid));
  }
  stampUuid(bytes, meta, frame.frame);
  return bytes;
}

}  // namespace detail

FrameData readVdbPointCache(const std::filesystem::path& path, VdbCacheContents* contents) {
  const std::string file = path.string();
  openvdb::initialize();
  const openvdb::GridBase::Ptr base = readVdbGrid(file, kGridName);
  const auto grid = openvdb::gridPtrCast<vdbp::PointDataGrid>(base);
  if (!grid) {
    throw std::runtime_error(where(file) + ": is a grid of type " + base->type() +
                             " (expected a PointDataGrid)");
  }
  const vdbp::PointDataTree& tree = grid->constTree();
  const openvdb::math::Transform& transform = grid->constTransform();
  const bool identity = isIdentity(transform);

  VdbCacheContents found;
  std::vector<openvdb::Vec3f> position, velocity;
  std::vector<std::int64_t> id;
  std::vector<float> age, life, mass;
  std::vector<std::string> customNames;
  std::vector<std::vector<float>> custom;
  bool first = true;
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
    checkLeaf(*leaf, file);
    const vdbp::AttributeSet::Descriptor& d = leaf->attributeSet().descriptor();
    // Every leaf of a PointDataGrid shares one descriptor: positions and names are the first
    // leaf's.
    const std::size_t pPos = d.find("P");
    if (pPos == vdbp::AttributeSet::INVALID_POS) {
      throw std::runtime_error(where(file) + ": the points have no attribute P");
    }
    if (!leaf->constAttributeArray(pPos).hasValueType<openvdb::Vec3f>()) {
      throw std::runtime_error(where(file) + ": P is of type " + d.valueType(pPos) +
                               " (expected vec3s)");
    }
    auto find = [&](const char* name, auto typed) {
      const std::size_t pos = d.find(name);
      using T = decltype(typed);
      if (pos == vdbp::AttributeSet::INVALID_POS) return pos;
      return leaf->constAttributeArray(pos).template hasValueType<T>()
                 ? pos
                 : vdbp::AttributeSet::INVALID_POS;
    };
    const std::size_t vPos = find("v", openvdb::Vec3f());
    const std::size_t idPos = find("id", std::int64_t());
    const std::size_t id32Pos = find("id", std::int32_t());
    const std::size_t agePos = find("age", float()), lifePos = find("life", float()),
                      massPos = find("mass", float());
    // Every other attribute of a type a frame holds, in the file's order: a float, an int32 (a
    // float column of whole numbers) or a vec3s (three columns: vectorColumns()).
    std::vector<std::size_t> customPos;
    std::vector<AttributeKind> customKinds;
    std::vector<std::string> names(d.size());
    for (const auto& [name, pos] : d.map()) names[pos] = name;
    for (std::size_t pos = 0; pos < d.size(); ++pos) {
      if (isStandard(names[pos])) continue;
      const vdbp::AttributeArray& array = leaf->constAttributeArray(pos);
      const bool isFloat = array.hasValueType<float>(), isInt = array.hasValueType<std::int32_t>(),
                 isVector = array.hasValueType<openvdb::Vec3f>();
      if (!isFloat && !isInt && !isVector) continue;
      customPos.push_back(pos);
      customKinds.push_back(isVector ? AttributeKind::Vec3
                            : isInt  ? AttributeKind::Int
                                     : AttributeKind::Float);
    }
    std::size_t customColumns = 0;
    for (AttributeKind k : customKinds) customColumns += k == AttributeKind::Vec3 ? 3 : 1;
    if (first) {
      found.hasVelocity = vPos != vdbp::AttributeSet::INVALID_POS;
      found.hasId =
          idPos != vdbp::AttributeSet::INVALID_POS || id32Pos != vdbp::AttributeSet::INVALID_POS;
      found.hasAge = agePos != vdbp::AttributeSet::INVALID_POS;
      found.hasLife = lifePos != vdbp::AttributeSet::INVALID_POS;
      found.hasMass = massPos != vdbp::AttributeSet::INVALID_POS;
      for (std::size_t a = 0; a < customPos.size(); ++a) {
        if (customKinds[a] != AttributeKind::Vec3) {
          customNames.push_back(names[customPos[a]]);
          continue;
        }
        for (const std::string& column : vectorColumns(names[customPos[a]]))
          customNames.push_back(column);
      }
      custom.resize(customNames.size());
      first = false;
    }

    vdbp::AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray(pPos));
    for (auto index = leaf->beginIndexAll(); index; ++index) {
      const openvdb::Coord ijk = index.getCoord();
      const openvdb::Vec3f o = p.get(*index);
      openvdb::Vec3f x;
      if (identity) {
        // (ijk + P) · 1 as OpenVDB computes it, but a coordinate of voxel 0 is P as stored, so
        // that −0.0 stays −0.0.
        for (int c = 0; c < 3; ++c) {
          x[c] = ijk[c] == 0
                     ? o[c]
                     : static_cast<float>(static_cast<double>(ijk[c]) + static_cast<double>(o[c]));
        }
      } else {
        const openvdb::Vec3d w = transform.indexToWorld(ijk.asVec3d() + openvdb::Vec3d(o));
        x = openvdb::Vec3f(static_cast<float>(w[0]), static_cast<float>(w[1]),
                           static_cast<float>(w[2]));
      }
      position.push_back(x);
    }
    const openvdb::Index count = leaf->pointCount();
    auto readAll = [&](std::size_t pos, auto& out, auto fallback) {
      using T = std::decay_t<decltype(fallback)>;
      if (pos == vdbp::AttributeSet::INVALID_POS) {
        out.insert(out.end(), count, fallback);
        return;
      }
      vdbp::AttributeHandle<T> h(leaf->constAttributeArray(pos));
      for (openvdb::Index k = 0; k < count; ++k) out.push_back(h.get(k));
    };
    readAll(vPos, velocity, openvdb::Vec3f(0.0f));
    if (idPos != vdbp::AttributeSet::INVALID_POS) {
      readAll(idPos, id, std::int64_t{0});
    } else if (id32Pos != vdbp::AttributeSet::INVALID_POS) {
      std::vector<std::int32_t> narrow;
      readAll(id32Pos, narrow, std::int32_t{0});
      id.insert(id.end(), narrow.begin(), narrow.end());
    } else {
      // Without an id the rows are numbered in file order.
      for (openvdb::Index k = 0; k < count; ++k) id.push_back(static_cast<std::int64_t>(id.size()));
    }
    readAll(agePos, age, 0.0f);
    readAll(lifePos, life, std::numeric_limits<float>::infinity());
    readAll(massPos, mass, 1.0f);
    if (customColumns != custom.size()) {
      throw std::runtime_error(where(file) + ": leaves with different attributes");
    }
    std::size_t column = 0;
    for (std::size_t a = 0; a < customPos.size(); ++a) {
      if (customKinds[a] == AttributeKind::Float) {
        readAll(customPos[a], custom[column++], 0.0f);
      } else if (customKinds[a] == AttributeKind::Int) {
        std::vector<std::int32_t> values;
        readAll(customPos[a], values, std::int32_t{0});
        for (std::int32_t v : values) custom[column].push_back(static_cast<float>(v));
        ++column;
      } else {
        std::vector<openvdb::Vec3f> values;
        readAll(customPos[a], values, openvdb::Vec3f(0.0f));
        for (int c = 0; c < 3; ++c, ++column) {
          for (const openvdb::Vec3f& v : values) custom[column].push_back(v[c]);
        }
      }
    }
    if (position.size() != id.size()) {
      throw std::runtime_error(where(file) + ": a leaf's offsets do not match its attributes");
    }
  }

  // Rows in id order (ids are unique in a tickfx cache; equal ids keep the file's order).
  const std::size_t n = position.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (found.hasId) {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return static_cast<std::uint64_t>(id[a]) < static_cast<std::uint64_t>(id[b]);
    });
  }
  FrameData frame;
  frame.resize(n, customNames);
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = order[r];
    const auto row = static_cast<Eigen::Index>(r);
    for (int c = 0; c < 3; ++c) {
      frame.position[c][row] = position[i][c];
      frame.velocity[c][row] = velocity[i][c];
    }
    frame.id[r] = static_cast<std::uint64_t>(id[i]);
    frame.age[row] = age[i];
    frame.life[row] = life[i];
    frame.mass[row] = mass[i];
    for (std::size_t a = 0; a < custom.size(); ++a) frame.attributes[a][row] = custom[a][i];
  }

  VdbCacheMetadata& meta = found.metadata;
  meta.effectHash = metaValue<std::string>(*grid, kMetaEffectHash).value_or("");
  meta.seed = static_cast<std::uint64_t>(metaValue<std::int64_t>(*grid, kMetaSeed).value_or(0));
  meta.stepRateHz = metaValue<std::int64_t>(*grid, kMetaStepRate).value_or(0);
  meta.integrator = metaValue<std::string>(*grid, kMetaIntegrator).value_or("");
  meta.tickfxVersion = metaValue<std::string>(*grid, kMetaVersion).value_or("");
  frame.frame = metaValue<std::int64_t>(*grid, kMetaFrame).value_or(0);
  frame.timeSeconds = metaValue<double>(*grid, kMetaTime).value_or(0.0);
  if (contents != nullptr) *contents = found;
  return frame;
}

}  // namespace tickfx::io
