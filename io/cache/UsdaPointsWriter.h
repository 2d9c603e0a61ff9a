// A run's frames as one USD layer in the text format (.usda): a Points prim whose attributes
// hold a time sample a frame, for Houdini Solaris, usdview, Omniverse and Blender 4 and later.
// (Debian packages no USD library: this writes the text grammar itself; io/cache/UsdaReader
// parses it back.)
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "io/cache/FrameData.h"
#include "io/util/AtomicFile.h"

namespace tickfx::io {

/// What a layer says about its time: its frames are time codes, `timeCodesPerSecond` of them a
/// second (the output's frame rate as a decimal: 24, 29.97002997002997 for 30000/1001).
struct UsdaLayerSettings {
  double timeCodesPerSecond = 24.0;
  std::string primName = "particles";  // the Points prim, /particles: the default prim
};

/// Writes frames one at a time into one .usda file, holding no more than a frame in memory. Each
/// attribute's time samples go to a stream of their own beside the file; finish() writes the
/// layer (metadata, the prim, each attribute with its samples) atomically and removes the
/// streams. A writer destroyed unfinished leaves nothing.
///
/// The prim, UsdGeomPoints with Houdini's attribute names as primvars:
///   point3f[] points (m), vector3f[] velocities (m/s), int64[] ids,
///   float[] primvars:age (s), primvars:life (s), primvars:mass (kg),
///   then the frame's attributes in its order: float[] widths = 2 · pscale (m),
///   color3f[] primvars:displayColor from Cd, float[] primvars:displayOpacity from Alpha, and
///   every other as primvars:NAME: int[] for whole-number attributes (hitnum), vector3f[] for
///   vectors (hitpos), float[] otherwise. Primvars have interpolation "vertex".
/// The layer: defaultPrim, startTimeCode and endTimeCode (the first and last frame written),
/// timeCodesPerSecond, upAxis "Y", metersPerUnit 1. Floats are written in the shortest form that
/// reads back to the same float (inf, -inf and nan as USD spells them), so a reader gets every bit
/// but a NaN's sign and payload.
class UsdaPointsWriter {
 public:
  /// Nothing appears at `path` before finish(); throws WriteError when the streams beside it
  /// cannot be made.
  UsdaPointsWriter(std::filesystem::path path, UsdaLayerSettings settings,
                   Durability durability = Durability::Renamed);
  ~UsdaPointsWriter();
  UsdaPointsWriter(const UsdaPointsWriter&) = delete;
  UsdaPointsWriter& operator=(const UsdaPointsWriter&) = delete;

  /// Appends `frame` at time code frame.frame. Frames come in rising order, each with the first
  /// frame's attributes (std::invalid_argument otherwise). Throws WriteError on a full disk.
  void write(const FrameData& frame);
  /// Writes the file from the frames so far (at least one: std::logic_error otherwise).
  void finish();

  const std::filesystem::path& path() const { return path_; }
  /// Whether a frame was written (finish() needs one).
  bool hasFrames() const { return started_; }

 private:
  struct Stream;
  void open(const FrameData& first);
  static const FloatColumn& columnOf(const FrameData& f, const Stream& s, int component);
  void removeStreams();

  std::filesystem::path path_;
  std::filesystem::path parts_;  // the streams' folder, beside path_
  UsdaLayerSettings settings_;
  Durability durability_;
  std::vector<std::string> attributeNames_;
  std::vector<std::unique_ptr<Stream>> streams_;
  std::int64_t first_ = 0, last_ = 0;
  bool started_ = false;
};

}  // namespace tickfx::io
