// remora._remora: the compiled half of the Python package `remora` (python/remora/ wraps it,
// checks keyword options and documents every function). Remora's exceptions become Python's:
// InvalidArgument -> ValueError, IoError -> OSError, NumericalError and any other remora::Error
// -> RuntimeError, std::bad_alloc -> MemoryError (pybind11's own translation).
#include <exception>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "remora/common/error.h"
#include "remora/linalg/solver.h"

namespace py = pybind11;

PYBIND11_MODULE(_remora, m) {
  m.doc() = "Remora's compiled core; use the package `remora`, which documents every function.";
  m.attr("__version__") = REMORA_VERSION;
#ifdef REMORA_WITH_GPL_SOLVERS
  m.attr("WITH_GPL_SOLVERS") = true;
#else
  m.attr("WITH_GPL_SOLVERS") = false;
#endif
  m.def("solver_names", &remora::solver_names);
  m.def("default_solver_name", &remora::default_solver_name);

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const remora::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const remora::InvalidArgument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const remora::Error& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });

  remora::python::bind_mesh(m);
  remora::python::bind_remesh(m);
  remora::python::bind_editor(m);
  remora::python::bind_systems(m);
}
