// Sequences of frame durations that drive a run: fixed rates, seeded jitter, or a recorded list.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "particles/Clock.h"

namespace tickfx::io {

/// Parses "60", "30000/1001" or "23.976"-free ratios: an integer or N/D with positive integers.
/// Throws std::invalid_argument with a message naming `text` when it is not one, or when a frame
/// at that rate is not a whole number of flicks.
FrameRate parseFrameRate(std::string_view text);

/// Frames of one `rate` covering exactly `total` flicks: whole frames, then one shorter last frame
/// if `total` is not a multiple (so the run ends exactly at `total`).
std::vector<Flicks> fixedRateFrames(FrameRate rate, Flicks total);

/// `count` frames of one `rate`.
std::vector<Flicks> fixedRateFrameCount(FrameRate rate, std::int64_t count);

/// A seeded sequence of frame durations uniform in [1/240 s, 1/10 s] (whole flicks), the last one
/// trimmed so that the sum is exactly `total`. A pure function of (`seed`, `total`).
std::vector<Flicks> jitteredFrames(std::uint64_t seed, Flicks total);

/// Reads one duration in seconds a line (blank lines and lines starting with '#' skipped), each
/// rounded to the nearest flick. Throws std::runtime_error naming the file and line of a bad value
/// (not a number, negative, not finite).
std::vector<Flicks> readFrameTimes(const std::filesystem::path& path);

}  // namespace tickfx::io
