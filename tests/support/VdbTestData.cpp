// The OpenVDB half of the tests (see VdbTestData.h): the only test translation unit that
// compiles OpenVDB's templates.
#include "VdbTestData.h"

#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointGroup.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/PointAdvect.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <stdexcept>
#include <utility>

#include "fields/vdb/RegisteredGrid.h"
#include "fields/vdb/VdbGridFile.h"
#include "fields/vdb/VectorFieldGrids.h"

namespace tickfx::vdb_test {
namespace {

namespace vdbp = openvdb::points;

// Each Compression's name and io::File flags (Default: none of its own, setCompression() is not
// called).
struct CompressionInfo {
  Compression compression;
  const char* name;
  std::uint32_t flags;
};
constexpr CompressionInfo kCompressions[] = {
    {Compression::Default, "default", 0},
    {Compression::None, "none", openvdb::io::COMPRESS_NONE},
    {Compression::Zip, "zip", openvdb::io::COMPRESS_ZIP},
    {Compression::ZipActiveMask, "zip|active_mask",
     openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK},
    {Compression::Blosc, "blosc", openvdb::io::COMPRESS_BLOSC},
    {Compression::BloscActiveMask, "blosc|active_mask",
     openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK},
};

const CompressionInfo& infoOf(Compression c) {
  for (const CompressionInfo& info : kCompressions) {
    if (info.compression == c) return info;
  }
  throw std::logic_error("no such Compression");
}

void writeGrids(const std::filesystem::path& path, const openvdb::GridCPtrVec& grids,
                Compression compression) {
  openvdb::io::File out(path.string());
  if (compression != Compression::Default) out.setCompression(infoOf(compression).flags);
  out.write(grids);
  out.close();
}

// A Value as the value type of a grid, and back.
template <typename T>
T valueAs(const Value& v) {
  if constexpr (openvdb::VecTraits<T>::IsVec) {
    using E = typename openvdb::VecTraits<T>::ElementType;
    return T(static_cast<E>(v[0]), static_cast<E>(v[1]), static_cast<E>(v[2]));
  } else {
    return static_cast<T>(v[0]);
  }
}
template <typename T>
Value valueOf(const T& t) {
  if constexpr (openvdb::VecTraits<T>::IsVec) {
    return {static_cast<double>(t[0]), static_cast<double>(t[1]), static_cast<double>(t[2])};
  } else {
    return {static_cast<double>(t), 0.0, 0.0};
  }
}

template <typename GridT>
openvdb::GridBase::Ptr makeGridAs(const GridFileSpec& spec) {
  using V = typename GridT::ValueType;
  typename GridT::Ptr grid = newRegisteredGrid<GridT>(valueAs<V>(spec.background));
  grid->setName(spec.name);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(spec.voxelSize));
  for (const auto& [ijk, value] : spec.activeVoxels) {
    grid->tree().setValueOn(openvdb::Coord(ijk[0], ijk[1], ijk[2]), valueAs<V>(value));
  }
  for (const GridTile& t : spec.tiles) {
    grid->tree().addTile(static_cast<openvdb::Index>(t.level),
                         openvdb::Coord(t.origin[0], t.origin[1], t.origin[2]), valueAs<V>(t.value),
                         t.active);
  }
  grid->setSaveFloatAsHalf(spec.halfFloats);
  return grid;
}

// The grid of `spec`, of its type.
openvdb::GridBase::Ptr makeGrid(const GridFileSpec& spec) {
  switch (spec.type) {
    case GridType::Float:
      return makeGridAs<openvdb::FloatGrid>(spec);
    case GridType::Double:
      return makeGridAs<openvdb::DoubleGrid>(spec);
    case GridType::Vec3s:
      return makeGridAs<openvdb::Vec3SGrid>(spec);
    case GridType::Vec3d:
      return makeGridAs<openvdb::Vec3DGrid>(spec);
  }
  throw std::logic_error("no such GridType");
}

template <typename GridT>
bool probe(const openvdb::GridBase::Ptr& base, const std::vector<Coord>& at, GridProbe& out) {
  const typename GridT::Ptr grid = openvdb::gridPtrCast<GridT>(base);
  if (!grid) return false;
  out.activeVoxelCount = grid->activeVoxelCount();
  for (const Coord& c : at) {
    const openvdb::Coord ijk(c[0], c[1], c[2]);
    out.values.push_back(valueOf(grid->tree().getValue(ijk)));
    out.active.push_back(grid->tree().isValueOn(ijk));
  }
  return true;
}

template <typename T>
void readMetadata(const openvdb::MetaMap& meta, std::map<std::string, T>& out) {
  for (auto it = meta.beginMeta(); it != meta.endMeta(); ++it) {
    if (const auto typed = openvdb::DynamicPtrCast<openvdb::TypedMetadata<T>>(it->second)) {
      out[it->first] = typed->value();
    }
  }
}

// Grid `name` of `path`, read by openvdb::io::File alone (no tickfx code), in memory.
openvdb::GridBase::Ptr readGridByOpenVdb(const std::filesystem::path& path,
                                         const std::string& name) {
  openvdb::initialize();
  openvdb::io::File in(path.string());
  in.open(false);
  const openvdb::GridBase::Ptr grid = in.readGrid(name);
  in.close();
  return grid;
}

}  // namespace

std::string toString(Compression compression) { return infoOf(compression).name; }

void writeGridFile(const std::filesystem::path& path, const GridFileSpec& spec) {
  writeGridsFile(path, {spec});
}

void writeGridsFile(const std::filesystem::path& path, const std::vector<GridFileSpec>& specs) {
  openvdb::initialize();
  openvdb::GridCPtrVec grids;
  for (const GridFileSpec& spec : specs) grids.push_back(makeGrid(spec));
  writeGrids(path, grids, specs.empty() ? Compression::Default : specs.front().compression);
}

void writePointsFile(const std::filesystem::path& path, const PointsFileSpec& spec) {
  openvdb::initialize();
  std::vector<openvdb::Vec3R> positions;
  for (const auto& p : spec.positions) positions.emplace_back(p[0], p[1], p[2]);
  const vdbp::PointAttributeVector<openvdb::Vec3R> wrapper(positions);
  const auto transform = openvdb::math::Transform::createLinearTransform(spec.voxelSize);
  const auto index =
      openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(wrapper, *transform);
  vdbp::PointDataGrid::Ptr grid;
  switch (spec.codec) {
    case PositionCodec::Null:
      grid = vdbp::createPointDataGrid<vdbp::NullCodec, vdbp::PointDataGrid>(*index, wrapper,
                                                                             *transform);
      break;
    case PositionCodec::FixedPoint16:
      grid = vdbp::createPointDataGrid<vdbp::FixedPointCodec<false>, vdbp::PointDataGrid>(
          *index, wrapper, *transform);
      break;
  }
  for (const PointAttributeSpec& a : spec.attributes) {
    using Type = PointAttributeSpec::Type;
    switch (a.type) {
      case Type::Float:
        vdbp::appendAttribute<float>(grid->tree(), a.name, a.value[0],
                                     static_cast<openvdb::Index>(a.stride));
        break;
      case Type::Int32:
        vdbp::appendAttribute<std::int32_t>(grid->tree(), a.name,
                                            static_cast<std::int32_t>(a.value[0]));
        break;
      case Type::Vec3s:
        vdbp::appendAttribute<openvdb::Vec3f>(grid->tree(), a.name,
                                              openvdb::Vec3f(a.value[0], a.value[1], a.value[2]));
        break;
      case Type::String:
        vdbp::appendAttribute<openvdb::Name>(grid->tree(), a.name);
        break;
      case Type::Group:
        vdbp::appendGroup(grid->tree(), a.name);
        break;
    }
  }
  grid->setName(spec.grid);
  writeGrids(path, {grid}, spec.compression);
}

PointsGridRead readPointsGrid(const std::filesystem::path& path, const std::string& name) {
  const openvdb::GridBase::Ptr base = readGridByOpenVdb(path, name);
  const auto grid = openvdb::gridPtrCast<vdbp::PointDataGrid>(base);
  if (!grid) {
    throw std::runtime_error(path.string() + ": grid '" + name + "' is a " + base->type() +
                             ", not a PointDataGrid");
  }
  PointsGridRead out;
  readMetadata(*grid, out.stringMetadata);
  readMetadata(*grid, out.int64Metadata);
  readMetadata(*grid, out.doubleMetadata);
  const openvdb::Vec3d voxel = grid->voxelSize();
  out.voxelSize = {voxel[0], voxel[1], voxel[2]};
  out.pointCount = vdbp::pointCount(grid->tree());
  out.activeVoxelCount = grid->tree().activeVoxelCount();

  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
    const vdbp::AttributeSet::Descriptor& d = leaf->attributeSet().descriptor();
    std::vector<PointAttributeInfo> infos(d.size());
    for (const auto& [attribute, pos] : d.map()) {
      infos[pos] = {attribute, d.valueType(pos), leaf->constAttributeArray(pos).codecType()};
    }
    out.leaves.push_back(infos);

    const vdbp::AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray("P"));
    std::vector<std::pair<std::string, vdbp::AttributeHandle<float>>> floats;
    std::vector<std::pair<std::string, vdbp::AttributeHandle<openvdb::Vec3f>>> vectors;
    std::vector<std::pair<std::string, vdbp::AttributeHandle<std::int64_t>>> ints;
    for (const PointAttributeInfo& a : infos) {
      const openvdb::points::AttributeArray& array = leaf->constAttributeArray(a.name);
      if (a.valueType == "float") {
        floats.emplace_back(a.name, vdbp::AttributeHandle<float>(array));
      } else if (a.valueType == "vec3s" && a.name != "P") {
        vectors.emplace_back(a.name, vdbp::AttributeHandle<openvdb::Vec3f>(array));
      } else if (a.valueType == "int64") {
        ints.emplace_back(a.name, vdbp::AttributeHandle<std::int64_t>(array));
      }
    }
    for (auto index = leaf->beginIndexOn(); index; ++index) {
      PointRead point;
      const openvdb::Coord ijk = index.getCoord();
      const openvdb::Vec3f offset = p.get(*index);
      const openvdb::Vec3d world =
          grid->transform().indexToWorld(ijk.asVec3d() + openvdb::Vec3d(offset));
      for (int c = 0; c < 3; ++c) {
        point.voxel[c] = ijk[c];
        point.offset[c] = offset[c];
        point.world[c] = static_cast<float>(world[c]);
      }
      for (const auto& [attribute, handle] : floats) {
        point.floats[attribute] = {handle.get(*index)};
      }
      for (const auto& [attribute, handle] : vectors) {
        const openvdb::Vec3f v = handle.get(*index);
        point.floats[attribute] = {v[0], v[1], v[2]};
      }
      for (const auto& [attribute, handle] : ints) {
        point.int64s[attribute] = handle.get(*index);
      }
      out.points.push_back(std::move(point));
    }
  }
  return out;
}

std::map<std::string, std::string> attributeTypes(const std::vector<PointAttributeInfo>& leaf) {
  std::map<std::string, std::string> types;
  for (const PointAttributeInfo& a : leaf) types[a.name] = a.valueType;
  return types;
}

GridProbe probeGridReadByTickfx(const std::filesystem::path& path, const std::string& grid,
                                const std::vector<Coord>& at) {
  const openvdb::GridBase::Ptr base = readVdbGrid(path.string(), grid);
  GridProbe out;
  out.type = base->type();
  if (probe<openvdb::FloatGrid>(base, at, out) || probe<openvdb::DoubleGrid>(base, at, out) ||
      probe<openvdb::Vec3SGrid>(base, at, out) || probe<openvdb::Vec3DGrid>(base, at, out)) {
    return out;
  }
  throw std::runtime_error(path.string() + ": grid '" + grid + "' is a " + out.type +
                           " (probeGridReadByTickfx reads float, double, vec3s and vec3d grids)");
}

std::unique_ptr<VectorField> oneVoxelFrames(const VectorField::Settings& settings, double voxelSize,
                                            const std::vector<Coord>& activeVoxel) {
  openvdb::initialize();
  std::map<Coord, openvdb::GridBase::Ptr> made;
  VectorField::Grids grids;
  for (const Coord& c : activeVoxel) {
    openvdb::GridBase::Ptr& grid = made[c];
    if (!grid) {
      auto g = newRegisteredGrid<openvdb::Vec3fGrid>();
      g->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
      g->tree().setValueOn(openvdb::Coord(c[0], c[1], c[2]), openvdb::Vec3f(0.0f));
      grid = g;
    }
    grids.grids.push_back(grid);
  }
  return std::make_unique<VectorField>(settings, grids);
}

Positions boxSamples(const std::filesystem::path& path, const std::string& grid,
                     const Positions& world, bool zeroOutside) {
  const openvdb::GridBase::Ptr base = readGridByOpenVdb(path, grid);
  const auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base);
  if (!g) {
    throw std::runtime_error(path.string() + ": grid '" + grid + "' is a " + base->type() +
                             ", not a vec3s grid");
  }
  auto acc = g->getConstAccessor();
  Positions out;
  out.reserve(world.size());
  for (const auto& w : world) {
    const openvdb::Vec3d index = g->transform().worldToIndex(openvdb::Vec3d(w[0], w[1], w[2]));
    openvdb::Vec3f u(0.0f);
    if (!zeroOutside || acc.isValueOn(openvdb::Coord::round(index)))
      openvdb::tools::BoxSampler::sample(acc, index, u);
    out.push_back({u[0], u[1], u[2]});
  }
  return out;
}

Positions advectWithPointAdvect(const AnalyticField& field, const BakeSettings& bake,
                                Positions points, const std::vector<float>& steps, unsigned order,
                                bool threaded) {
  openvdb::initialize();
  const openvdb::Vec3fGrid::Ptr grid = bakeGrid(field, bake);
  std::vector<openvdb::Vec3f> list;
  list.reserve(points.size());
  for (const auto& p : points) list.emplace_back(p[0], p[1], p[2]);
  openvdb::tools::PointAdvect<openvdb::Vec3fGrid, std::vector<openvdb::Vec3f>, false> advector(
      *grid);
  advector.setIntegrationOrder(order);
  advector.setThreaded(threaded);
  for (const float dt : steps) advector.advect(list, dt, 1);
  for (std::size_t i = 0; i < list.size(); ++i) {
    for (int c = 0; c < 3; ++c) points[i][static_cast<std::size_t>(c)] = list[i][c];
  }
  return points;
}

}  // namespace tickfx::vdb_test
