// Where `tickfx preview` takes its frames from: a run of an effect, or a folder of caches.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io/cache/FrameData.h"

namespace tickfx::app {

/// Pairs of particle ids drawn as lines: a structure's springs.
using IdPairs = std::vector<std::pair<std::uint64_t, std::uint64_t>>;

/// A sequence of frames that can be walked more than once, giving the same frames each time.
class PreviewSource {
 public:
  virtual ~PreviewSource() = default;

  /// The frame numbers there are, ascending (1..N for an effect; the files' for a folder).
  virtual const std::vector<std::int64_t>& frames() const = 0;
  /// What the caption calls the sequence: the effect file's or the folder's name.
  virtual std::string name() const = 0;
  /// Frames per second, for flipbooks (24 when the frames do not say).
  virtual double fps() const = 0;
  /// Whether the frames carry their times (CSV caches do not).
  virtual bool knowsTimes() const = 0;
  /// A frame with no particle but the columns and attributes the frames have.
  virtual io::FrameData sample() const = 0;

  /// Walks the frames from the first to `last`, calling `visit` with each frame `wanted` accepts
  /// and the id pairs drawn as lines in it.
  virtual void walk(std::int64_t last, const std::function<bool(std::int64_t)>& wanted,
                    const std::function<void(const io::FrameData&, const IdPairs&)>& visit) = 0;
};

/// The source `path` names: a folder of caches (io::listCacheFrames) or an effect file, loaded
/// with `overrides` and built for an offline run. Bad input prints its diagnostics to stderr and
/// gives nothing.
std::unique_ptr<PreviewSource> openPreviewSource(const std::string& path,
                                                 const std::vector<std::string>& overrides);

}  // namespace tickfx::app
