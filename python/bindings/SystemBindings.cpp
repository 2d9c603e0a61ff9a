// tickfx.System: a loaded effect's ParticleSystem, its clock, and numpy windows onto its pool.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fields/ForceSet.h"
#include "io/cache/FrameData.h"
#include "io/effect/EffectLoader.h"
#include "particles/StateHash.h"
#include "python/bindings/Bindings.h"

namespace tickfx::python {
namespace {

// Bytes of one row of the pool's columns: position, velocity, previous position and acceleration
// (12 floats), lifetime and mass (2 floats), id (8 bytes), birth tick (4) and the dead flag; a
// custom attribute adds a float.
constexpr double kPoolBytesPerRow = 12 * 4 + 2 * 4 + 8 + 4 + 1;

std::string gigabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", bytes / 1e9);
  return text;
}

/// What Python holds: the system, the effect it was built from and what a VDB cache records of it.
class PySystem {
 public:
  PySystem(std::unique_ptr<ParticleSystem> system, io::EffectSettings effect, std::string path,
           std::string effectHash)
      : system_(std::move(system)),
        effect_(std::move(effect)),
        path_(std::move(path)),
        effectHash_(std::move(effectHash)) {
    // positions(alpha) interpolates after step() as after advance().
    system_->setKeepPreviousPositions(true);
  }

  ParticleSystem& system() { return *system_; }
  const ParticleSystem& system() const { return *system_; }
  const io::EffectSettings& effect() const { return effect_; }
  const std::string& path() const { return path_; }
  const std::string& effectHash() const { return effectHash_; }

  // A numpy view keeps a raw pointer into the pool, and the pool's columns move when a spawn
  // grows them. Growing them once to max_particles, before the first view exists, means they never
  // move again: spawns past max_particles are refused, not grown into. Storage size does not
  // change the simulation (row blocks depend on the row count alone).
  void pinStorage() {
    if (pinned_) return;
    ParticlePool& pool = system_->editPool();
    // Some of the columns are zero-filled as they grow: a reservation past the machine's memory
    // would not fail as an exception but get the interpreter killed.
    const double bytes = static_cast<double>(pool.maxParticles()) *
                         (kPoolBytesPerRow + 4.0 * static_cast<double>(pool.attributeCount()));
    const double physical =
        static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGESIZE));
    if (physical > 0.0 && bytes > physical) {
      const std::string message =
          "the first view of a system reserves simulation.max_particles = " +
          std::to_string(pool.maxParticles()) + " rows (" + gigabytes(bytes) +
          "), more than this machine's " + gigabytes(physical) +
          " of memory: load the effect with a smaller max_particles (overrides "
          "{\"simulation.max_particles\": N})";
      PyErr_SetString(PyExc_MemoryError, message.c_str());
      throw py::error_already_set();
    }
    pool.reserve(pool.maxParticles());
    pinned_ = true;
  }

 private:
  std::unique_ptr<ParticleSystem> system_;
  io::EffectSettings effect_;
  std::string path_;
  std::string effectHash_;
  bool pinned_ = false;
};

std::vector<SettingOverride> toOverrides(
    const std::vector<std::pair<std::string, std::string>>& kv) {
  std::vector<SettingOverride> overrides;
  overrides.reserve(kv.size());
  for (const auto& [key, value] : kv) overrides.push_back({key, value});
  return overrides;
}

// The system's `owner` is the numpy base: the array keeps the System object (and its pool) alive.
template <typename T>
py::array readOnlyView(const T* data, std::size_t rows, py::handle owner) {
  py::array view(py::dtype::of<T>(), {static_cast<py::ssize_t>(rows)},
                 {static_cast<py::ssize_t>(sizeof(T))}, data, owner);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

PySystem& pinned(py::handle self) {
  PySystem& s = self.cast<PySystem&>();
  s.pinStorage();
  return s;
}

py::tuple vec3View(const Vec3Column& column, std::size_t rows, py::handle owner) {
  return py::make_tuple(readOnlyView(column.x.data(), rows, owner),
                        readOnlyView(column.y.data(), rows, owner),
                        readOnlyView(column.z.data(), rows, owner));
}

constexpr const char* kViewNote =
    "\n\nA zero-copy, read-only window onto the pool's rows [0, count) as they were when taken "
    "(the state after the newest tick, not interpolated to `time`). Later steps may reorder or "
    "refill those rows and add rows past them: take a new view after stepping. The first view of "
    "a system reserves storage for simulation.max_particles rows (about 69 bytes each), so that "
    "the pool never moves while views exist. A view keeps its System alive.";

std::string viewDoc(const std::string& what) { return what + kViewNote; }

// A zero-copy view of one column of the pool: what the pool's `Column` accessor returns.
template <typename Column>
struct ColumnView {
  const char* name;
  const Column& (ParticlePool::*column)() const;
  const char* doc;
};

template <typename Column>
void bindColumnViews(py::class_<PySystem>& system,
                     std::initializer_list<ColumnView<Column>> views) {
  for (const ColumnView<Column>& v : views) {
    system.def_property_readonly(
        v.name,
        [column = v.column](py::object self) {
          const ParticlePool& pool = pinned(self).system().pool();
          return readOnlyView((pool.*column)().data(), pool.size(), self);
        },
        viewDoc(v.doc).c_str());
  }
}

void bindNonfiniteEvent(py::module_& m) {
  py::class_<NonfiniteEvent>(
      m, "NonfiniteEvent",
      "The tick that left particles with a non-finite position or velocity, under "
      "simulation.nonfinite = \"stop\" (System.nonfinite_stop). str() gives the message "
      "`tickfx run` prints.")
      .def_readonly(
          "tick", &NonfiniteEvent::tick,
          "Ticks done: the state at tick / step_rate seconds is the first non-finite one.")
      .def_property_readonly("time", &NonfiniteEvent::seconds, "tick / step_rate, in seconds.")
      .def_readonly("particles", &NonfiniteEvent::particles,
                    "How many particles have a non-finite position or velocity component.")
      .def_readonly("first_ids", &NonfiniteEvent::firstIds,
                    "The ids of the first of them (at most 8), increasing.")
      .def("__str__", &NonfiniteEvent::describe)
      .def("__repr__",
           [](const NonfiniteEvent& e) { return "<NonfiniteEvent " + e.describe() + ">"; });
}

void bindSystemClass(py::module_& m) {
  py::class_<PySystem> cls(
      m, "System",
      "A running effect, made by tickfx.load_effect(). Advance it frame by frame "
      "with advance() (or tick by tick with step()), read its particles through "
      "the zero-copy views (positions, velocities, ids, ...) or as copies "
      "(interpolated_positions(), capture()). Not thread-safe: drive a system "
      "from one thread.");
  cls.def("_advance_flicks",
          [](PySystem& s, std::int64_t flicks) {
            if (flicks < 0) throw py::value_error("a frame lasts 0 flicks or more");
            const AdvanceResult r = s.system().advance(flicks);
            return py::make_tuple(r.ticks, r.ticksDropped);
          })
      .def(
          "step",
          [](PySystem& s, std::int64_t ticks) {
            if (ticks < 0) throw py::value_error("step(ticks): ticks must be >= 0");
            s.system().stepTicks(ticks);
          },
          py::arg("ticks") = 1,
          "Runs `ticks` ticks (each 1/step_rate seconds) now, bypassing the frame clock of "
          "advance(); the shown time is then the newest tick's (alpha = 1). advance() keeps a "
          "frame clock that step() does not move: after mixing the two, advance() still runs "
          "the ticks its own clock asks for.")
      .def_property_readonly(
          "tick", [](const PySystem& s) { return s.system().tickCount(); },
          "Ticks completed: the pool holds the state after tick `tick` - 1, at tick / step_rate "
          "seconds.")
      .def_property_readonly(
          "alpha", [](const PySystem& s) { return s.system().alpha(); },
          "Where the shown time lies between the previous and the newest tick, in [0, 1] (1: on "
          "the newest tick, after step() or a frame that ends on a tick).")
      .def_property_readonly(
          "time", [](const PySystem& s) { return s.system().shownSeconds(); },
          "Seconds the last frame shows (the time advance() reached; the newest tick's after "
          "step()), as a float for display: the clock itself is exact.")
      .def_property_readonly(
          "count", [](const PySystem& s) { return s.system().pool().size(); },
          "Particles alive after the newest tick.")
      .def_property_readonly(
          "step_rate", [](const PySystem& s) { return s.system().settings().stepRateHz; },
          "Ticks per second (Hz): simulation.step_rate.")
      .def_property_readonly(
          "max_particles", [](const PySystem& s) { return s.system().pool().maxParticles(); },
          "simulation.max_particles: spawns past it are refused.")
      .def_property_readonly(
          "output_fps",
          [](const PySystem& s) {
            const FrameRate fps = s.effect().output.fps;
            return py::module_::import("fractions")
                .attr("Fraction")(fps.numerator, fps.denominator);
          },
          "The effect's output frame rate, frames per second, as an exact fractions.Fraction "
          "(30000/1001 for NTSC): advance(1 / output_fps) is one frame.")
      .def_property_readonly(
          "output_frames", [](const PySystem& s) { return s.effect().output.frameCount(); },
          "Frames the effect's [output] asks for (what `tickfx run` writes).")
      .def_property_readonly(
          "path", [](const PySystem& s) { return s.path(); },
          "The effect file, as given to load_effect().")
      .def_property_readonly(
          "attribute_names",
          [](const PySystem& s) {
            std::vector<std::string> names;
            const ParticlePool& pool = s.system().pool();
            for (std::size_t a = 0; a < pool.attributeCount(); ++a)
              names.push_back(pool.attributeName(a));
            return names;
          },
          "Names of the pool's custom float attributes (see attribute()).")
      .def_property_readonly(
          "nonfinite_stop",
          [](const PySystem& s) -> py::object {
            const auto& event = s.system().nonfiniteStop();
            return event ? py::cast(*event) : py::none();
          },
          "None, or the NonfiniteEvent of the tick that left particles non-finite under "
          "simulation.nonfinite = \"stop\": advance() and step() then run no more ticks, and the "
          "state stays the one that tick made.")
      .def_property_readonly(
          "nonfinite_killed", [](const PySystem& s) { return s.system().nonfiniteKilled(); },
          "Particles removed for a non-finite position or velocity under simulation.nonfinite = "
          "\"kill\".")
      .def(
          "state_hash", [](const PySystem& s) { return hashToHex(stateHash(s.system())); },
          "The state hash after the newest tick: the 16 hex digits `tickfx run --hash` prints as "
          "state-hash (every column of every particle, bit for bit).")
      .def_property_readonly(
          "positions",
          [](py::object self) {
            const ParticlePool& pool = pinned(self).system().pool();
            return vec3View(pool.position(), pool.size(), self);
          },
          viewDoc("Positions in metres as (x, y, z), three 1-D float32 arrays (the pool is "
                  "structure-of-arrays).")
              .c_str())
      .def_property_readonly(
          "velocities",
          [](py::object self) {
            const ParticlePool& pool = pinned(self).system().pool();
            return vec3View(pool.velocity(), pool.size(), self);
          },
          viewDoc("Velocities in metres per second as (x, y, z), three 1-D float32 arrays.")
              .c_str())
      .def(
          "attribute",
          [](py::object self, const std::string& name) {
            PySystem& s = self.cast<PySystem&>();
            const std::size_t a = s.system().pool().findAttribute(name);
            if (a == ParticlePool::npos) throw py::key_error(name);
            const ParticlePool& pool = pinned(self).system().pool();
            return readOnlyView(pool.attribute(a).data(), pool.size(), self);
          },
          py::arg("name"),
          viewDoc("The custom float attribute `name` as float32 (KeyError when the pool has no "
                  "such attribute; see attribute_names).")
              .c_str())
      .def(
          "interpolated_positions",
          [](const PySystem& s, std::optional<double> alpha) {
            const ParticleSystem& system = s.system();
            const std::size_t n = system.pool().size();
            py::array_t<float> out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(n), 3});
            float* xyz = out.mutable_data();
            if (!alpha) {
              system.copyRenderPositions(Vec3Destination::interleaved(xyz, n));
              return out;
            }
            if (!(*alpha >= 0.0 && *alpha <= 1.0)) {
              throw py::value_error("interpolated_positions: alpha must be in [0, 1]");
            }
            Vec3Column columns;
            system.interpolatedPositions(static_cast<float>(*alpha), columns);
            for (std::size_t i = 0; i < n; ++i) {
              const auto r = static_cast<Eigen::Index>(i);
              xyz[3 * i] = columns.x[r];
              xyz[3 * i + 1] = columns.y[r];
              xyz[3 * i + 2] = columns.z[r];
            }
            return out;
          },
          py::arg("alpha") = py::none(),
          "Positions in metres as a new (count, 3) float32 array. alpha=None: the positions at "
          "the shown time (`time`), exactly what `tickfx run` writes for the frame. Else "
          "previous + (newest - previous) * alpha between the last two ticks, alpha in [0, 1] "
          "(rounded to float32): exactly the previous tick's positions at 0, the newest tick's "
          "at 1.")
      .def(
          "capture",
          [](const PySystem& s) {
            return frameToDict(io::captureFrame(s.system(), 0, s.system().shownSeconds()));
          },
          "The particles as the shown frame has them, as read_cache() returns a cache (new "
          "arrays): P (metres) and v (metres per second) at the shown time as (count, 3) "
          "float32, id int64, age (seconds) at the shown time, life (seconds), mass (kg) and the "
          "custom attributes: Houdini's hit attributes when the effect records hits (hitnum "
          "int32; hittime in seconds; hitpos, hitnml and hitv as (count, 3) float32), others "
          "float32. write_cache(path, system.capture(), ...) writes what "
          "`tickfx run` writes for the frame.")
      .def("__repr__", [](const PySystem& s) {
        return "<tickfx.System " + s.path() + " tick=" + std::to_string(s.system().tickCount()) +
               " count=" + std::to_string(s.system().pool().size()) + ">";
      });
  cls.def_property_readonly(
      "ages",
      [](const PySystem& s) {
        const ParticlePool& pool = s.system().pool();
        py::array_t<float> ages(static_cast<py::ssize_t>(pool.size()));
        pool.ages(0, pool.size(), ages.mutable_data());
        return ages;
      },
      "Ages in seconds at the newest tick, as a new float32 array: the pool keeps birth ticks, "
      "and works ages out from them where they are read (exactly the ages a cache of that tick "
      "holds).");
  bindColumnViews<RowColumn<std::uint64_t>>(
      cls, {{"ids", &ParticlePool::id,
             "Particle ids, uint64, unique per system and increasing with birth (rows are in "
             "id order)."}});
  bindColumnViews<FloatColumn>(
      cls,
      {{"lifetimes", &ParticlePool::lifetime, "Lifetimes in seconds, float32 (inf: never dies)."},
       {"masses", &ParticlePool::mass, "Masses in kilograms, float32 (inf: pinned)."}});
}

}  // namespace

void bindSystem(py::module_& m) {
  bindNonfiniteEvent(m);
  bindSystemClass(m);

  m.def(
      "_load_effect",
      [](const std::string& path, const std::vector<std::pair<std::string, std::string>>& kv,
         std::optional<int> threads, bool offline) {
        const std::vector<SettingOverride> overrides = toOverrides(kv);
        LoadOptions options;
        options.threads = threads;
        options.offline = offline;
        LoadedEffect loaded;
        std::string hash;
        {
          // Loading reads and may bake vector fields: other Python threads may run meanwhile.
          py::gil_scoped_release release;
          loaded = loadEffect(path, overrides, options);
          if (loaded.ok()) hash = hashToHex(loaded.fingerprint);
        }
        std::vector<std::string> lines;
        for (const io::Diagnostic& d : loaded.diagnostics) lines.push_back(d.format());
        if (!loaded.ok()) return py::make_tuple(py::none(), lines);
        auto system = std::make_unique<PySystem>(std::move(loaded.system),
                                                 std::move(*loaded.effect), path, std::move(hash));
        return py::make_tuple(py::cast(std::move(system)), lines);
      },
      py::arg("path"), py::arg("overrides"), py::arg("threads"), py::arg("offline"));

  m.def(
      "_check",
      [](const std::string& path, const std::vector<std::pair<std::string, std::string>>& kv) {
        std::vector<io::Diagnostic> diagnostics;
        {
          py::gil_scoped_release release;
          diagnostics = checkEffect(path, toOverrides(kv));
        }
        std::vector<std::pair<bool, std::string>> lines;
        for (const io::Diagnostic& d : diagnostics)
          lines.emplace_back(d.severity == io::Severity::Error, d.format());
        return lines;
      },
      py::arg("path"), py::arg("overrides"));

  m.def(
      "_vdb_metadata",
      [](const PySystem& s) {
        const SystemSettings& settings = s.system().settings();
        return py::make_tuple(s.effectHash(), settings.seed, settings.stepRateHz,
                              settings.integrator);
      },
      py::arg("system"));
}

}  // namespace tickfx::python
