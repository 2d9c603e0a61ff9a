#include "io/cache/AttributeGroups.h"

#include "particles/LifeAttribute.h"

namespace tickfx::io {

std::array<std::string, 3> vectorColumns(const std::string& name) {
  return vectorColumnNames(name);
}

bool isIntAttribute(const std::string& name) {
  return name == "hitnum" || name == "contacts" || name == "emitter";
}

namespace {

// The vec3 whose first column is `column`, or "".
std::string vectorNamed(const std::string& column) {
  if (column == "Cd_r") return "Cd";
  if (column.size() > 2 && column.compare(column.size() - 2, 2, "_x") == 0)
    return column.substr(0, column.size() - 2);
  return "";
}

}  // namespace

std::vector<AttributeGroup> attributeGroups(const std::vector<std::string>& columns) {
  std::vector<AttributeGroup> groups;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const std::string vector = vectorNamed(columns[c]);
    if (!vector.empty() && c + 2 < columns.size()) {
      const std::array<std::string, 3> names = vectorColumns(vector);
      if (columns[c + 1] == names[1] && columns[c + 2] == names[2]) {
        groups.push_back({vector, AttributeKind::Vec3, c});
        c += 2;
        continue;
      }
    }
    groups.push_back(
        {columns[c], isIntAttribute(columns[c]) ? AttributeKind::Int : AttributeKind::Float, c});
  }
  return groups;
}

}  // namespace tickfx::io
