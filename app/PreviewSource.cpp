#include "app/PreviewSource.h"

#include <cstdio>
#include <filesystem>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "app/FrameTimes.h"
#include "app/LoadEffect.h"
#include "fields/SpringNetwork.h"
#include "io/cache/CacheFolder.h"
#include "io/effect/EffectBuilder.h"
#include "io/effect/EffectLoader.h"
#include "io/effect/EffectParser.h"
#include "particles/ParticleSystem.h"

namespace tickfx::app {
namespace {

// An effect's frames: each walk runs the effect afresh (the state at a frame is a pure function
// of the effect, so every walk sees the same frames).
class EffectFrames final : public PreviewSource {
 public:
  EffectFrames(io::EffectSettings effect, std::string name)
      : effect_(std::move(effect)), name_(std::move(name)) {
    frames_.resize(static_cast<std::size_t>(effect_.output.frameCount()));
    std::iota(frames_.begin(), frames_.end(), std::int64_t{1});
    // Building loads the effect's fields: a file that does not load is bad input, found here.
    system_ = io::buildOfflineSystem(effect_, std::nullopt);
  }

  const std::vector<std::int64_t>& frames() const override { return frames_; }
  std::string name() const override { return name_; }
  double fps() const override {
    return static_cast<double>(effect_.output.fps.numerator) /
           static_cast<double>(effect_.output.fps.denominator);
  }
  bool knowsTimes() const override { return true; }
  io::FrameData sample() const override { return io::captureFrame(*system_, 0, 0.0); }

  void walk(std::int64_t last, const std::function<bool(std::int64_t)>& wanted,
            const std::function<void(const io::FrameData&, const IdPairs&)>& visit) override {
    if (!system_) system_ = io::buildOfflineSystem(effect_, std::nullopt);
    const Flicks length = lengthOfFrames(
        effect_.output.fps, static_cast<std::int64_t>(frames_.size()), "output length");
    FrameSchedule schedule = FrameSchedule::fixedRate(effect_.output.fps, length);
    while (const std::optional<Flicks> d = schedule.next()) {
      system_->advance(*d);
      const std::int64_t f = schedule.framesDone();
      if (f > last) break;
      if (!wanted(f)) continue;
      IdPairs lines;
      if (const SpringNetwork* springs = system_->springs()) {
        for (const Spring& s : springs->springs()) lines.emplace_back(s.a, s.b);
      }
      visit(io::captureFrame(*system_, f, system_->shownSeconds()), lines);
    }
    system_.reset();  // the next walk starts from the beginning
  }

 private:
  io::EffectSettings effect_;
  std::string name_;
  std::vector<std::int64_t> frames_;
  std::unique_ptr<ParticleSystem> system_;
};

// A folder of caches, read file by file.
class CacheFrames final : public PreviewSource {
 public:
  explicit CacheFrames(const std::filesystem::path& directory)
      : files_(io::listCacheFrames(directory)),
        name_(std::filesystem::absolute(directory).lexically_normal().filename().string()) {
    if (name_.empty()) {
      name_ =
          std::filesystem::absolute(directory).lexically_normal().parent_path().filename().string();
    }
    for (const io::CacheFrameFile& f : files_) frames_.push_back(f.frame);
    first_ = io::readCacheFrame(files_.front());
    // The caches' own times give the rate; a single frame, or frames without times, 24 fps.
    knowsTimes_ = first_.timeSeconds != 0.0;
    if (files_.size() > 1) {
      const io::FrameData last = io::readCacheFrame(files_.back());
      const double seconds = last.timeSeconds - first_.timeSeconds;
      const auto steps = static_cast<double>(files_.back().frame - files_.front().frame);
      if (seconds > 0.0 && steps > 0.0) fps_ = steps / seconds;
      knowsTimes_ = knowsTimes_ || seconds != 0.0;
    }
  }

  const std::vector<std::int64_t>& frames() const override { return frames_; }
  std::string name() const override { return name_; }
  double fps() const override { return fps_; }
  bool knowsTimes() const override { return knowsTimes_; }
  io::FrameData sample() const override {
    io::FrameData empty;
    empty.resize(0, first_.attributeNames);
    return empty;
  }

  void walk(std::int64_t last, const std::function<bool(std::int64_t)>& wanted,
            const std::function<void(const io::FrameData&, const IdPairs&)>& visit) override {
    for (const io::CacheFrameFile& file : files_) {
      if (file.frame > last) break;
      if (wanted(file.frame)) visit(io::readCacheFrame(file), {});
    }
  }

 private:
  std::vector<io::CacheFrameFile> files_;
  std::string name_;
  std::vector<std::int64_t> frames_;
  io::FrameData first_;
  double fps_ = 24.0;
  bool knowsTimes_ = false;
};

}  // namespace

std::unique_ptr<PreviewSource> openPreviewSource(const std::string& path,
                                                 const std::vector<std::string>& overrides) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    try {
      return std::make_unique<CacheFrames>(path);
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return nullptr;
    }
  }
  const io::LoadResult load = loadEffectReporting(path, overrides);
  if (!load.ok()) return nullptr;
  try {
    return std::make_unique<EffectFrames>(*load.effect,
                                          std::filesystem::path(path).stem().string());
  } catch (const io::BuildError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return nullptr;
  }
}

}  // namespace tickfx::app
