// The extension tickfx._tickfx. Users import tickfx (python/tickfx/__init__.py), which wraps it.
#include <pybind11/pybind11.h>

#include "particles/Clock.h"
#include "python/bindings/Bindings.h"

PYBIND11_MODULE(_tickfx, m) {
  namespace py = pybind11;
  m.doc() = "tickfx's C++ core; import tickfx instead.";
  m.attr("__version__") = TICKFX_VERSION;
  m.attr("FLICKS_PER_SECOND") = py::int_(tickfx::kFlicksPerSecond);
  py::register_exception<tickfx::python::CacheFailure>(m, "CacheError", PyExc_OSError);
  tickfx::python::bindSystem(m);
  tickfx::python::bindCaches(m);
}
