// How a frame's named float columns are written where a cache format has types.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace tickfx::io {

enum class AttributeKind { Float, Int, Vec3 };

/// One attribute as a typed format stores it: columns [column, column + 3) of the frame's
/// attributes for a Vec3, [column, column + 1) otherwise.
struct AttributeGroup {
  std::string name;
  AttributeKind kind = AttributeKind::Float;
  std::size_t column = 0;
};

/// The columns a vec3 attribute `name` is held in: `Cd_r`, `Cd_g`, `Cd_b` for Houdini's colour,
/// `<name>_x`, `_y`, `_z` for any other.
std::array<std::string, 3> vectorColumns(const std::string& name);

/// Whether Houdini's attribute `name` is an integer (`hitnum`): its column holds whole numbers,
/// written as 32-bit integers where the format has them. So are `contacts` (every
/// contact, for collision sub-emitters) and `emitter` (the index of the emitter that made the row).
bool isIntAttribute(const std::string& name);

/// `columns` (a frame's attribute names, in order) as attributes: three consecutive columns
/// vectorColumns(n) make the vec3 `n`; a column isIntAttribute() names an Int; any other a Float.
std::vector<AttributeGroup> attributeGroups(const std::vector<std::string>& columns);

}  // namespace tickfx::io
