// What the parts of the extension tickfx._tickfx share.
#pragma once

#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>

#include "io/cache/FrameData.h"

namespace tickfx::python {

namespace py = pybind11;

/// A cache that could not be read or written (a missing, truncated or malformed file, an
/// unwritable folder): tickfx.CacheError in Python, an OSError.
class CacheFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `frame` as read_cache() returns a cache: P and v as (N, 3) float32, id as int64 (the ids'
/// bits), age, life, mass and every custom attribute as float32, all new arrays. Throws
/// py::value_error when a custom attribute has the name of a standard column.
py::dict frameToDict(const io::FrameData& frame);

void bindSystem(py::module_& m);
void bindCaches(py::module_& m);

}  // namespace tickfx::python
