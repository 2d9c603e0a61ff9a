#include "io/cache/UsdaPointsWriter.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <system_error>

#include "io/cache/AttributeGroups.h"

namespace tickfx::io {
namespace {

// A float in the shortest form that reads back to it; USD's spellings of the non-finite.
void appendFloat(std::string& out, float v) {
  if (std::isnan(v)) {
    out += "nan";
    return;
  }
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  out.append(text, end);
}

void appendInt(std::string& out, std::int64_t v) {
  char text[24];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  out.append(text, end);
}

// A double (time codes per second) in its shortest form.
std::string doubleText(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

}  // namespace

// One attribute's time samples, written as they come to a file of their own.
struct UsdaPointsWriter::Stream {
  std::string type;  // "point3f[]", "float[]", ...
  std::string name;  // "points", "primvars:age", ...
  bool primvar = false;
  // What it reads of a frame: a fixed column, or the attributes from index `attribute` on (three
  // for a vector).
  enum class Column { Position, Velocity, Age, Life, Mass, Attribute } column = Column::Attribute;
  std::size_t attribute = 0;
  enum class Kind { Float, Int, Vec3, Ids, Width } kind = Kind::Float;
  std::filesystem::path file;
  std::ofstream out;
};

UsdaPointsWriter::UsdaPointsWriter(std::filesystem::path path, UsdaLayerSettings settings,
                                   Durability durability)
    : path_(std::move(path)), settings_(std::move(settings)), durability_(durability) {
  requireWritable(path_);
  parts_ = path_;
  parts_ += ".parts";
  std::error_code ec;
  std::filesystem::remove_all(parts_, ec);
  if (!std::filesystem::create_directory(parts_, ec)) {
    throw WriteError(parts_, ec ? ec.message() : "cannot make the folder");
  }
}

UsdaPointsWriter::~UsdaPointsWriter() { removeStreams(); }

void UsdaPointsWriter::removeStreams() {
  streams_.clear();  // closes the files
  std::error_code ec;
  std::filesystem::remove_all(parts_, ec);
}

void UsdaPointsWriter::open(const FrameData& first) {
  attributeNames_ = first.attributeNames;
  using Column = Stream::Column;
  const auto add = [&](std::string type, std::string name, Stream::Kind kind, Column column,
                       std::size_t attribute, bool primvar) {
    auto s = std::make_unique<Stream>();
    s->type = std::move(type);
    s->name = std::move(name);
    s->kind = kind;
    s->column = column;
    s->attribute = attribute;
    s->primvar = primvar;
    s->file = parts_ / (std::to_string(streams_.size()) + ".samples");
    s->out.open(s->file, std::ios::binary);
    if (!s->out) throw WriteError(s->file, "cannot open");
    streams_.push_back(std::move(s));
  };
  add("point3f[]", "points", Stream::Kind::Vec3, Column::Position, 0, false);
  add("vector3f[]", "velocities", Stream::Kind::Vec3, Column::Velocity, 0, false);
  add("int64[]", "ids", Stream::Kind::Ids, Column::Attribute, 0, false);
  add("float[]", "primvars:age", Stream::Kind::Float, Column::Age, 0, true);
  add("float[]", "primvars:life", Stream::Kind::Float, Column::Life, 0, true);
  add("float[]", "primvars:mass", Stream::Kind::Float, Column::Mass, 0, true);
  // The attributes in the frame's order (a reader rebuilds that order), Houdini's radius, colour
  // and opacity under UsdGeom's names.
  for (const AttributeGroup& g : attributeGroups(first.attributeNames)) {
    if (g.name == "pscale" && g.kind == AttributeKind::Float) {
      add("float[]", "widths", Stream::Kind::Width, Column::Attribute, g.column, false);
    } else if (g.name == "Cd" && g.kind == AttributeKind::Vec3) {
      add("color3f[]", "primvars:displayColor", Stream::Kind::Vec3, Column::Attribute, g.column,
          true);
    } else if (g.name == "Alpha" && g.kind == AttributeKind::Float) {
      add("float[]", "primvars:displayOpacity", Stream::Kind::Float, Column::Attribute, g.column,
          true);
    } else if (g.kind == AttributeKind::Vec3) {
      add("vector3f[]", "primvars:" + g.name, Stream::Kind::Vec3, Column::Attribute, g.column,
          true);
    } else if (g.kind == AttributeKind::Int) {
      add("int[]", "primvars:" + g.name, Stream::Kind::Int, Column::Attribute, g.column, true);
    } else {
      add("float[]", "primvars:" + g.name, Stream::Kind::Float, Column::Attribute, g.column, true);
    }
  }
}

// Component `component` of what stream `s` reads of frame `f`.
const FloatColumn& UsdaPointsWriter::columnOf(const FrameData& f, const Stream& s, int component) {
  switch (s.column) {
    case Stream::Column::Position:
      return f.position[component];
    case Stream::Column::Velocity:
      return f.velocity[component];
    case Stream::Column::Age:
      return f.age;
    case Stream::Column::Life:
      return f.life;
    case Stream::Column::Mass:
      return f.mass;
    case Stream::Column::Attribute:
      break;
  }
  return f.attributes[s.attribute + static_cast<std::size_t>(component)];
}

void UsdaPointsWriter::write(const FrameData& frame) {
  if (!started_) {
    open(frame);
    first_ = frame.frame;
    started_ = true;
  } else {
    if (frame.frame <= last_) {
      throw std::invalid_argument("frame " + std::to_string(frame.frame) + " after frame " +
                                  std::to_string(last_) + " (frames come in rising order)");
    }
    if (frame.attributeNames != attributeNames_) {
      throw std::invalid_argument("frame " + std::to_string(frame.frame) +
                                  " has other attributes than the first frame");
    }
  }
  last_ = frame.frame;
  const std::size_t n = frame.size();
  std::string line;
  for (const auto& s : streams_) {
    line.clear();
    line.reserve(16 + n * (s->kind == Stream::Kind::Vec3 ? 36 : 12));
    line += "        ";
    appendInt(line, frame.frame);
    line += ": [";
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0) line += ", ";
      const auto r = static_cast<Eigen::Index>(i);
      switch (s->kind) {
        case Stream::Kind::Ids:
          appendInt(line, static_cast<std::int64_t>(frame.id[i]));
          break;
        case Stream::Kind::Int:
          appendInt(line, static_cast<std::int64_t>(columnOf(frame, *s, 0)[r]));
          break;
        case Stream::Kind::Float:
          appendFloat(line, columnOf(frame, *s, 0)[r]);
          break;
        case Stream::Kind::Width:  // a diameter: twice the radius, exact in float
          appendFloat(line, 2.0f * columnOf(frame, *s, 0)[r]);
          break;
        case Stream::Kind::Vec3:
          line += '(';
          for (int c = 0; c < 3; ++c) {
            if (c > 0) line += ", ";
            appendFloat(line, columnOf(frame, *s, c)[r]);
          }
          line += ')';
          break;
      }
    }
    line += "],\n";
    s->out.write(line.data(), static_cast<std::streamsize>(line.size()));
    if (!s->out) throw WriteError(path_, "cannot write the samples of " + s->name);
  }
}

void UsdaPointsWriter::finish() {
  if (!started_) throw std::logic_error("a .usda layer of no frame");
  for (const auto& s : streams_) {
    s->out.close();
    if (!s->out) throw WriteError(path_, "cannot write the samples of " + s->name);
  }
  writeFileAtomically(
      path_,
      [&](std::ostream& out) {
        out << "#usda 1.0\n(\n"
            << "    defaultPrim = \"" << settings_.primName << "\"\n"
            << "    endTimeCode = " << last_ << "\n"
            << "    metersPerUnit = 1\n"
            << "    startTimeCode = " << first_ << "\n"
            << "    timeCodesPerSecond = " << doubleText(settings_.timeCodesPerSecond) << "\n"
            << "    upAxis = \"Y\"\n)\n\n"
            << "def Points \"" << settings_.primName << "\"\n{\n";
        for (const auto& s : streams_) {
          if (s->primvar) {
            out << "    " << s->type << " " << s->name
                << " (\n        interpolation = \"vertex\"\n    )\n";
          }
          out << "    " << s->type << " " << s->name << ".timeSamples = {\n";
          std::ifstream in(s->file, std::ios::binary);
          out << in.rdbuf();
          out << "    }\n";
        }
        out << "}\n";
      },
      durability_);
  removeStreams();
}

}  // namespace tickfx::io
