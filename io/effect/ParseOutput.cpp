#include "io/effect/ParseOutput.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "io/cache/CacheFormat.h"
#include "io/cache/VdbCacheOptions.h"
#include "particles/Clock.h"

namespace tickfx::io::detail {
namespace {

constexpr std::int64_t kMaxFrameRatePart = 1'000'000;

const std::vector<std::string> kCacheFormats = [] {
  std::vector<std::string> names;
  for (const CacheFormat f : kCacheFormatList) names.emplace_back(cacheFormatName(f));
  return names;
}();

// "30000/1001" or "24" as a frame rate.
std::optional<FrameRate> parseRatio(std::string_view text) {
  const auto readPart = [](std::string_view part) -> std::optional<std::int64_t> {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (ec != std::errc() || end != part.data() + part.size() || part.empty()) return std::nullopt;
    return v;
  };
  const std::size_t slash = text.find('/');
  const auto num = readPart(text.substr(0, slash));
  const auto den = slash == std::string_view::npos ? std::optional<std::int64_t>(1)
                                                   : readPart(text.substr(slash + 1));
  if (!num || !den) return std::nullopt;
  return FrameRate{*num, *den};
}

void readFps(Context& cx, TableReader& r, OutputSettings& out) {
  const toml::node* node = r.take("fps");
  if (node == nullptr) return;
  const std::string path = r.pathOf("fps");
  const std::string expected =
      "frames per second, an integer from 1 to 1000000 or a ratio string like \"30000/1001\"";
  std::optional<FrameRate> rate;
  std::string shown;
  if (const auto s = node->value_exact<std::string>()) {
    rate = parseRatio(*s);
    shown = quote(*s);
    if (!rate) {
      cx.error(cx.at(*node), path, shown + " is not a frame rate (expected " + expected + ")");
      return;
    }
  } else if (const auto i = node->value_exact<std::int64_t>()) {
    rate = FrameRate{*i, 1};
    shown = std::to_string(*i);
  } else {
    cx.error(cx.at(*node), path, describe(*node) + " (expected " + expected + ")");
    return;
  }
  if (rate->numerator < 1 || rate->numerator > kMaxFrameRatePart || rate->denominator < 1 ||
      rate->denominator > kMaxFrameRatePart) {
    cx.error(cx.at(*node), path, shown + " is out of range (expected " + expected + ")");
    return;
  }
  try {
    frameDuration(*rate);
  } catch (const std::invalid_argument&) {
    cx.error(cx.at(*node), path,
             shown +
                 " frames per second do not last a whole number of flicks (expected a rate "
                 "whose frame is a whole number of 1/705600000 s, such as 24, 25, 30, 60, 120 "
                 "or \"30000/1001\")");
    return;
  }
  cx.record(path, *node);
  out.fps = *rate;
}

}  // namespace

void readOutput(Context& cx, const toml::table& table, OutputSettings& out) {
  TableReader r(cx, table, "output");
  readFps(cx, r, out);
  const bool hasSeconds = r.number("seconds", out.seconds, "seconds, a number > 0 and <= 1e9",
                                   Range{0.0, kMaxRunSeconds, true});
  std::int64_t frames = 0;
  if (r.integer("frames", frames, "an integer from 1 to 1000000000", 1, kMaxRunFrames)) {
    if (hasSeconds || table.get("seconds") != nullptr) {
      cx.error(cx.at(*table.get("frames")), r.pathOf("frames"),
               "given together with output.seconds (expected either seconds or frames)");
    } else {
      out.frames = frames;
    }
  }
  if (const toml::node* node = r.take("formats")) {
    const std::string path = r.pathOf("formats");
    if (const toml::array* array = node->as_array()) {
      std::vector<CacheFormat> formats;
      bool ok = true;
      for (std::size_t i = 0; i < array->size(); ++i) {
        const std::string entryPath = childPath(path, i);
        const auto name = checkChoice(cx, *array->get(i), entryPath, kCacheFormats, "cache format");
        if (!name) {
          ok = false;
          continue;
        }
        const CacheFormat f = *cacheFormatFromName(*name);  // checkChoice took a known name
        if (std::find(formats.begin(), formats.end(), f) != formats.end()) {
          cx.error(cx.at(*array->get(i)), entryPath,
                   quote(*name) + " is listed twice (expected each format at most once)");
          ok = false;
          continue;
        }
        formats.push_back(f);
      }
      if (ok) {
        cx.record(path, *node);
        out.formats = formats;
      }
    } else {
      cx.error(
          cx.at(*node), path,
          describe(*node) + " (expected an array of cache formats, such as [\"csv\", \"ply\"])");
    }
  }
  r.string("directory", out.directory, "a directory path, a non-empty string");
  std::string name;
  if (r.choice("vdb_compression", name, vdbCompressionNames(), "VDB compression"))
    out.vdb.compression = *vdbCompressionNamed(name);
  if (r.choice("vdb_positions", name, vdbPositionsNames(), "VDB positions"))
    out.vdb.positions = *vdbPositionsNamed(name);
  r.boolean("hits", out.hits);
  r.finish();
}

}  // namespace tickfx::io::detail
