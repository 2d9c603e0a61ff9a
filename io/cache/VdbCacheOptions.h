// How VDB point caches are stored: compression and position precision, opt-in each.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tickfx::io {

/// How a VDB points cache is stored beyond its values. The defaults keep every bit and write
/// fastest; each other choice is opt-in and says what it costs.
struct VdbCacheOptions {
  enum class Compression {
    /// Attribute arrays stored as they are in memory (the default).
    None,
    /// OpenVDB's blosc (LZ4, byte shuffle) on every attribute array: lossless, smaller files
    /// (velocities and ages compress well, positions little), slower to write: every 1 MiB page
    /// of every attribute is compressed (tickfx compresses the pages in parallel, once each, where
    /// OpenVDB 10's own writer compresses each on one thread, twice: once to size it).
    /// OpenVDB's zip reaches only the voxel offsets of point data, not its attributes, so it is
    /// not offered.
    Blosc,
  };
  enum class Positions {
    /// P as 32-bit floats: every coordinate reads back with its exact bits (the default).
    Exact,
    /// P as 16-bit fixed point within its 1 m voxel (OpenVDB's "fxpt16", Houdini's default for
    /// VDB points): 6 bytes a point instead of 12, coordinates to within 1/65535 m (15 µm). A
    /// coordinate beyond ±2³⁰ m keeps only its sign (±0.5 m) and a NaN reads as
    /// −7.6 µm (the code nearest 0).
    Fixed16,
  };
  Compression compression = Compression::None;
  Positions positions = Positions::Exact;
};

/// "none" or "blosc".
std::string_view vdbCompressionName(VdbCacheOptions::Compression compression);
/// Every compression's name, in the order of VdbCacheOptions::Compression.
const std::vector<std::string>& vdbCompressionNames();
/// The compression called `name`, or nothing.
std::optional<VdbCacheOptions::Compression> vdbCompressionNamed(std::string_view name);
/// "exact" or "fixed16".
std::string_view vdbPositionsName(VdbCacheOptions::Positions positions);
/// Every positions' name, in the order of VdbCacheOptions::Positions.
const std::vector<std::string>& vdbPositionsNames();
/// The positions called `name`, or nothing.
std::optional<VdbCacheOptions::Positions> vdbPositionsNamed(std::string_view name);

}  // namespace tickfx::io
