// tickfx.read_cache and the core of tickfx.write_cache: frame caches (.csv, .ply, .vdb, and a
// frame of a run's .usda layer) as dicts of numpy arrays keyed by Houdini's attribute names.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "io/cache/AttributeGroups.h"
#include "io/cache/CsvCache.h"
#include "io/cache/PlyCache.h"
#include "io/cache/UsdaReader.h"
#include "io/cache/VdbPointCache.h"
#include "python/bindings/Bindings.h"

namespace tickfx::python {
namespace {

enum class Format { Csv, Ply, Vdb, Usda };

const char* const kStandardNames[] = {"P", "v", "id", "age", "life", "mass"};

Format formatOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".csv") return Format::Csv;
  if (ext == ".ply") return Format::Ply;
  if (ext == ".vdb") return Format::Vdb;
  if (ext == ".usda") return Format::Usda;
  throw py::value_error(path + ": not a cache file name (expected .csv, .ply, .vdb or .usda)");
}

py::array_t<float> floats(const FloatColumn& column) {
  py::array_t<float> out(column.size());
  if (column.size() > 0)
    std::memcpy(out.mutable_data(), column.data(), sizeof(float) * column.size());
  return out;
}

py::array_t<float> rowsOf3(const Vec3Column& column, std::size_t n) {
  py::array_t<float> out(std::vector<py::ssize_t>{static_cast<py::ssize_t>(n), 3});
  float* xyz = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    for (int c = 0; c < 3; ++c) xyz[3 * i + static_cast<std::size_t>(c)] = column[c][r];
  }
  return out;
}

// Runs `io` without the GIL, C++ failures of the file turned into CacheError; bad arguments stay
// ValueError and memory exhaustion MemoryError, as pybind11 translates them.
template <typename F>
auto guardedIo(F&& io) {
  try {
    py::gil_scoped_release release;
    return io();
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw CacheFailure(e.what());
  }
}

// Names the reader of each format could not read back as they were written.
void checkNames(Format format, const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    if (name.empty()) throw py::value_error("a custom attribute needs a name");
    const bool csvBreaks = name.find_first_of(",\r\n") != std::string::npos;
    const bool plyBreaks = std::any_of(name.begin(), name.end(), [](unsigned char c) {
      return std::isspace(c) != 0 || std::iscntrl(c) != 0;
    });
    if ((format == Format::Csv && csvBreaks) || (format == Format::Ply && plyBreaks)) {
      throw py::value_error("custom attribute '" + name + "' cannot be a column name of a " +
                            (format == Format::Csv
                                 ? "CSV cache (no commas or line breaks)"
                                 : "PLY cache (no spaces or control characters)"));
    }
  }
}

template <typename T>
const T* dataOf(const py::array_t<T, py::array::c_style>& a, std::size_t rows, std::size_t width,
                const char* name) {
  const bool ok = width == 1 ? (a.ndim() == 1 && static_cast<std::size_t>(a.shape(0)) == rows)
                             : (a.ndim() == 2 && static_cast<std::size_t>(a.shape(0)) == rows &&
                                static_cast<std::size_t>(a.shape(1)) == width);
  if (!ok) throw py::value_error(std::string(name) + ": wrong shape");
  return a.data();
}

using Floats = py::array_t<float, py::array::c_style>;
using Ids = py::array_t<std::uint64_t, py::array::c_style>;

void writeCache(
    const std::string& path, const Ids& ids, const Floats& p, const Floats& v, const Floats& age,
    const Floats& life, const Floats& mass, const std::vector<std::string>& names,
    const std::vector<Floats>& attributes, std::int64_t frameNumber, double timeSeconds,
    const std::optional<std::tuple<std::string, std::uint64_t, std::int64_t, std::string>>&
        metadata) {
  const Format format = formatOf(path);
  if (format == Format::Usda) {
    throw py::value_error(path +
                          ": a .usda layer holds a whole run, a time sample a frame "
                          "(write it with tickfx run --format usda)");
  }
  if (ids.ndim() != 1) throw py::value_error("id: wrong shape");
  if (names.size() != attributes.size()) throw py::value_error("one name per custom attribute");
  checkNames(format, names);
  const auto n = static_cast<std::size_t>(ids.shape(0));
  const std::uint64_t* id = ids.data();
  if (format == Format::Ply) {
    // PLY has no 64-bit integer type: ids are doubles, exact only up to 2^53.
    for (std::size_t i = 0; i < n; ++i) {
      if (id[i] > (std::uint64_t{1} << 53)) {
        throw py::value_error("id " + std::to_string(id[i]) +
                              " is past 2^53: a PLY cache stores ids as doubles and would not "
                              "read it back (use .csv or .vdb)");
      }
    }
  }
  io::FrameData frame;
  frame.frame = frameNumber;
  frame.timeSeconds = timeSeconds;
  frame.resize(n, names);
  std::copy(id, id + n, frame.id.begin());
  const float* xyz = dataOf(p, n, 3, "P");
  const float* vel = dataOf(v, n, 3, "v");
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    for (int c = 0; c < 3; ++c) {
      frame.position[c][r] = xyz[3 * i + static_cast<std::size_t>(c)];
      frame.velocity[c][r] = vel[3 * i + static_cast<std::size_t>(c)];
    }
  }
  auto fill = [&](FloatColumn& to, const Floats& from, const char* name) {
    const float* values = dataOf(from, n, 1, name);
    std::copy(values, values + n, to.data());
  };
  fill(frame.age, age, "age");
  fill(frame.life, life, "life");
  fill(frame.mass, mass, "mass");
  for (std::size_t a = 0; a < attributes.size(); ++a)
    fill(frame.attributes[a], attributes[a], names[a].c_str());

  io::VdbCacheMetadata meta;
  meta.tickfxVersion = TICKFX_VERSION;
  if (metadata) std::tie(meta.effectHash, meta.seed, meta.stepRateHz, meta.integrator) = *metadata;
  guardedIo([&] {
    if (format == Format::Csv) io::writeCsvCache(frame, path);
    if (format == Format::Ply) io::writePlyCache(frame, path);
    if (format == Format::Vdb) io::writeVdbPointCache(frame, meta, path);
  });
}

}  // namespace

py::dict frameToDict(const io::FrameData& frame) {
  const std::size_t n = frame.size();
  py::dict out;
  out["P"] = rowsOf3(frame.position, n);
  out["v"] = rowsOf3(frame.velocity, n);
  // Houdini's id is a signed integer: the uint64 ids' bits, as the VDB cache stores them.
  py::array_t<std::int64_t> id(static_cast<py::ssize_t>(n));
  if (n > 0) std::memcpy(id.mutable_data(), frame.id.data(), sizeof(std::int64_t) * n);
  out["id"] = id;
  out["age"] = floats(frame.age);
  out["life"] = floats(frame.life);
  out["mass"] = floats(frame.mass);
  // Houdini's types: a vec3 (hitpos, Cd) as (N, 3), an int (hitnum) as int32, others float32.
  for (const io::AttributeGroup& g : io::attributeGroups(frame.attributeNames)) {
    if (out.contains(g.name)) {
      const bool standard = std::find(std::begin(kStandardNames), std::end(kStandardNames),
                                      g.name) != std::end(kStandardNames);
      throw py::value_error("custom attribute '" + g.name + "' " +
                            (standard ? "has the name of a standard column" : "appears twice"));
    }
    const FloatColumn& column = frame.attributes[g.column];
    if (g.kind == io::AttributeKind::Vec3) {
      Vec3Column v{column, frame.attributes[g.column + 1], frame.attributes[g.column + 2]};
      out[py::str(g.name)] = rowsOf3(v, n);
    } else if (g.kind == io::AttributeKind::Int) {
      py::array_t<std::int32_t> ints(static_cast<py::ssize_t>(n));
      for (std::size_t i = 0; i < n; ++i)
        ints.mutable_data()[i] = static_cast<std::int32_t>(column[static_cast<Eigen::Index>(i)]);
      out[py::str(g.name)] = ints;
    } else {
      out[py::str(g.name)] = floats(column);
    }
  }
  return out;
}

void bindCaches(py::module_& m) {
  m.def(
      "_vector_columns",
      [](const std::string& name) {
        const std::array<std::string, 3> c = io::vectorColumns(name);
        return std::vector<std::string>(c.begin(), c.end());
      },
      py::arg("name"));
  m.def(
      "_read_cache",
      [](const std::string& path, std::optional<std::int64_t> frameNumber) {
        const Format format = formatOf(path);
        if (frameNumber && format != Format::Usda) {
          throw py::value_error(path + ": frame= picks a frame of a .usda layer; a ." +
                                std::string(format == Format::Csv   ? "csv"
                                            : format == Format::Ply ? "ply"
                                                                    : "vdb") +
                                " cache is one frame");
        }
        const io::FrameData frame = guardedIo([&] {
          if (format == Format::Csv) return io::readCsvCache(path);
          if (format == Format::Ply) return io::readPlyCache(path);
          if (format == Format::Vdb) return io::readVdbPointCache(path);
          if (frameNumber) return io::readUsdaFrame(path, *frameNumber);
          const std::vector<std::int64_t> frames = io::usdaFrames(path);
          if (frames.empty()) throw std::runtime_error(path + ": holds no frame");
          return io::readUsdaFrame(path, frames.front());
        });
        return frameToDict(frame);
      },
      py::arg("path"), py::arg("frame") = py::none());
  m.def(
      "_cache_info",
      [](const std::string& path) {
        const Format format = formatOf(path);
        if (format == Format::Usda)
          throw py::value_error(path + ": a .usda layer is a whole run: usda_frames() lists it");
        io::VdbCacheContents contents;
        const io::FrameData frame = guardedIo([&] {
          if (format == Format::Csv) return io::readCsvCache(path);
          if (format == Format::Ply) return io::readPlyCache(path);
          return io::readVdbPointCache(path, &contents);
        });
        // What the file records and nothing more: a CSV cache records no frame or time, a PLY
        // cache no run.
        py::dict out;
        py::object none = py::none();
        const bool timed = format != Format::Csv;
        out["frame"] = timed ? py::object(py::int_(frame.frame)) : none;
        out["time"] = timed ? py::object(py::float_(frame.timeSeconds)) : none;
        out["points"] = frame.size();
        const io::VdbCacheMetadata& meta = contents.metadata;
        const bool run = format == Format::Vdb && !meta.effectHash.empty();
        out["effect_hash"] = run ? py::object(py::str(meta.effectHash)) : none;
        out["seed"] = run ? py::object(py::int_(meta.seed)) : none;
        out["step_rate"] = run ? py::object(py::int_(meta.stepRateHz)) : none;
        out["integrator"] = run ? py::object(py::str(meta.integrator)) : none;
        out["version"] = run ? py::object(py::str(meta.tickfxVersion)) : none;
        return out;
      },
      py::arg("path"));
  m.def(
      "_usda_frames",
      [](const std::string& path) { return guardedIo([&] { return io::usdaFrames(path); }); },
      py::arg("path"));

  m.def("_write_cache", &writeCache, py::arg("path"), py::arg("id"), py::arg("P"), py::arg("v"),
        py::arg("age"), py::arg("life"), py::arg("mass"), py::arg("names"), py::arg("attributes"),
        py::arg("frame"), py::arg("time"), py::arg("metadata"));
}

}  // namespace tickfx::python
