// OpenVDB's side of the tests: the .vdb files and in-memory grids the tests hand to tickfx, what
// tickfx wrote read back through OpenVDB, and OpenVDB's tools::PointAdvect as an oracle.
//
// This header includes no OpenVDB header, and must not: its one translation unit
// (VdbTestData.cpp, the library tickfx_test_vdbdata) is the only test code that compiles
// OpenVDB's templates, once per build and, in the sanitizer build, without instrumentation (see
// tests/CMakeLists.txt for why and the figures). The code under test stays in tickfx_vdb and
// tickfx_io, instrumented; where a function here calls it, the documentation says so.
//
// Units: positions and voxel sizes in metres, world space unless said otherwise; Coord is an
// index-space (voxel) coordinate. Nothing here keeps state; every function may be called from
// any test and calls openvdb::initialize() itself. Errors are exceptions: OpenVDB's own, or
// std::runtime_error where this code checks something.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fields/vdb/AnalyticField.h"
#include "fields/vdb/VectorField.h"

namespace tickfx::vdb_test {

/// An index-space (voxel) coordinate, as openvdb::Coord.
using Coord = std::array<int, 3>;
/// A value of any grid type written here: scalar grids use [0] (and read back with [1], [2] 0).
using Value = std::array<double, 3>;
/// Points, world positions in metres.
using Positions = std::vector<std::array<float, 3>>;

// ---- files as OpenVDB writes them -------------------------------------------------------------

/// How openvdb::io::File compresses a file (openvdb::io::COMPRESS_* flags).
enum class Compression {
  Default,  // setCompression() not called: io::File's default (blosc, active mask)
  None,
  Zip,
  ZipActiveMask,
  Blosc,
  BloscActiveMask,
};
/// "blosc|active_mask" and the like, for SCOPED_TRACE.
std::string toString(Compression compression);

/// The grid types of writeGridFile: openvdb::FloatGrid, DoubleGrid, Vec3SGrid, Vec3DGrid.
enum class GridType { Float, Double, Vec3s, Vec3d };

/// A tile (Tree::addTile): one value, on or off, in the table of the node of tree level `level`
/// that holds voxel `origin`, standing for a child: 8³ voxels at level 1 and 128³ at level 2
/// (internal nodes), 4096³ at level 3 (the root).
struct GridTile {
  int level = 1;
  Coord origin{};
  Value value{};
  bool active = true;
};

/// One grid of a dense type. Values are converted to the grid's type: give float grids values
/// that are exact in float.
struct GridFileSpec {
  std::string name = "vel";
  GridType type = GridType::Vec3s;
  double voxelSize = 1.0;  // metres, a linear transform: voxel ijk's centre is at ijk·voxelSize
  Value background{};
  std::vector<std::pair<Coord, Value>> activeVoxels;  // set on, in this order
  std::vector<GridTile> tiles;                        // added after the voxels, in this order
  bool halfFloats = false;                            // GridBase::setSaveFloatAsHalf
  Compression compression = Compression::Default;
};

/// Writes the grid of `spec` as the only grid of a new file `path` (replacing it), with
/// openvdb::io::File.
void writeGridFile(const std::filesystem::path& path, const GridFileSpec& spec);
/// Writes the grids of `specs`, in this order, as the only grids of a new file `path` (replacing
/// it), with the first's compression (io::File compresses a whole file alike).
void writeGridsFile(const std::filesystem::path& path, const std::vector<GridFileSpec>& specs);

/// An attribute that every point of writePointsFile gets with the same value
/// (openvdb::points::appendAttribute), or an empty group (appendGroup).
struct PointAttributeSpec {
  enum class Type { Float, Int32, Vec3s, String, Group };
  std::string name;
  Type type = Type::Float;
  /// Float, Int32: value[0] (Int32: a whole number); Vec3s: all three; String (empty strings) and
  /// Group: unused.
  std::array<float, 3> value{};
  int stride = 1;  // Float only: values per point
};

/// How a points file's positions are stored: openvdb::points::NullCodec (floats) or
/// FixedPointCodec<false> (16 bits per component within the voxel).
enum class PositionCodec { Null, FixedPoint16 };

/// Points as another tool writes them: OpenVDB's own conversion of world positions
/// (tools::createPointIndexGrid, points::createPointDataGrid) into a PointDataGrid.
struct PointsFileSpec {
  std::string grid = "points";
  std::vector<std::array<double, 3>> positions;  // world, metres (openvdb::Vec3R)
  double voxelSize = 1.0;                        // metres
  PositionCodec codec = PositionCodec::Null;
  std::vector<PointAttributeSpec> attributes;  // appended in this order, after P
  Compression compression = Compression::Default;
};

/// Writes the points of `spec` as the only grid of a new file `path` (replacing it), with
/// openvdb::io::File.
void writePointsFile(const std::filesystem::path& path, const PointsFileSpec& spec);

// ---- tickfx's output read back through OpenVDB -------------------------------------------------

/// An attribute as a leaf's descriptor of a PointDataGrid has it.
struct PointAttributeInfo {
  std::string name;
  std::string valueType;  // "vec3s", "float", "int64", ...
  std::string codec;      // the array's codecType(): "null", "fxpt16", ...
};

/// One point as OpenVDB gives it.
struct PointRead {
  Coord voxel{};                  // the index-space voxel holding the point
  std::array<float, 3> offset{};  // P: the position within the voxel, in voxels
  std::array<float, 3> world{};   // float(transform.indexToWorld(voxel + P)), per component
  /// Every float and vec3s attribute but P, by name: one value (float) or three (vec3s).
  std::map<std::string, std::vector<float>> floats;
  std::map<std::string, std::int64_t> int64s;  // every int64 attribute, by name
};

/// A PointDataGrid read by OpenVDB alone (io::File, no tickfx code), for checking what tickfx
/// wrote with the tool a pipeline would use. Attributes of other value types are listed in
/// `leaves`, not read; metadata of other types is left out.
struct PointsGridRead {
  std::map<std::string, std::string> stringMetadata;
  std::map<std::string, std::int64_t> int64Metadata;
  std::map<std::string, double> doubleMetadata;
  std::array<double, 3> voxelSize{};  // metres
  std::uint64_t pointCount = 0;       // openvdb::points::pointCount(tree)
  std::uint64_t activeVoxelCount = 0;
  /// Each leaf's attributes in descriptor order, leaves in the tree's order (so the leaf count).
  std::vector<std::vector<PointAttributeInfo>> leaves;
  std::vector<PointRead> points;  // leaf by leaf, in each leaf's index order
};

/// Reads grid `grid` of `path`. Throws std::runtime_error when the grid is not a PointDataGrid,
/// OpenVDB's exceptions for a missing file or grid.
PointsGridRead readPointsGrid(const std::filesystem::path& path, const std::string& grid);

/// A leaf's attributes (one of PointsGridRead::leaves) by name: name → value type.
std::map<std::string, std::string> attributeTypes(const std::vector<PointAttributeInfo>& leaf);

/// A grid as tickfx's checked reader gives it, looked at through OpenVDB.
struct GridProbe {
  std::string type;  // GridBase::type(): "Tree_vec3s_5_4_3", "Tree_double_5_4_3", ...
  std::uint64_t activeVoxelCount = 0;
  std::vector<Value> values;  // the value at each voxel asked for, in order
  std::vector<bool> active;   // whether each voxel asked for is on
};

/// Reads grid `grid` of `path` with readVdbGrid (fields/vdb/VdbGridFile.h: the code under test, in
/// tickfx_vdb) and looks up each voxel of `at` in what it returns. Grid types other than
/// GridType's throw std::runtime_error; readVdbGrid's errors pass through.
GridProbe probeGridReadByTickfx(const std::filesystem::path& path, const std::string& grid,
                                const std::vector<Coord>& at);

// ---- in-memory grids and OpenVDB's tools ------------------------------------------------------

/// A VectorField over grids in memory (VectorField(settings, Grids): the code under test), one
/// grid a frame: vec3s, voxels of `voxelSize` metres, zero everywhere, and active only in the
/// voxel `activeVoxel[f]` for frame f. Frames with the same voxel share one grid, as the frames
/// of a held sequence do.
std::unique_ptr<VectorField> oneVoxelFrames(const VectorField::Settings& settings, double voxelSize,
                                            const std::vector<Coord>& activeVoxel);

/// The sampling oracle: what openvdb::tools::BoxSampler gives for the Vec3SGrid `grid` of `path`
/// (read by openvdb::io::File) at each world position, its index from the grid's transform
/// (worldToIndex), through one accessor for all of them; with `zeroOutside`, zero where the voxel
/// nearest to the index (Coord::round) is inactive. VectorField's trilinear sampling, done by
/// OpenVDB alone.
Positions boxSamples(const std::filesystem::path& path, const std::string& grid,
                     const Positions& world, bool zeroOutside);

/// The comparison oracle for advection: openvdb::tools::PointAdvect<Vec3fGrid,
/// std::vector<Vec3f>, false> (no constraint) advects `points` through bakeGrid(field, bake)
/// (fields/vdb/VectorFieldGrids.h, tickfx's bake, the grid bakeVectorField samples): one
/// advect(points, dt, 1) call for each dt of `steps` (seconds), at integration order `order`
/// (1 to 4), threaded or not (every option set explicitly: the copy constructor and some paths
/// leave members unset). Returns the points where PointAdvect leaves them, in order.
Positions advectWithPointAdvect(const AnalyticField& field, const BakeSettings& bake,
                                Positions points, const std::vector<float>& steps, unsigned order,
                                bool threaded);

}  // namespace tickfx::vdb_test
