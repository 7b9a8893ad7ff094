// The `_safecass` module: `import safecass` loads it (tools/python/safecass/__init__.py).
#include "bindings.hpp"

PYBIND11_MODULE(_safecass, m) {
  m.doc() = "SAFECASS's C++ core, bound for Python (docs/python.md); import safecass, not this module.";
  m.attr("__version__") = SAFECASS_VERSION;
  safecass::python::bind_values(m);
  safecass::python::bind_system(m);
  safecass::python::bind_runs(m);
  safecass::python::bind_recording(m);
  safecass::python::bind_remote(m);
}
