/// \file module.cpp
/// The `ellreloc._ellreloc` extension: every component's bindings, and the library's errors as
/// Python exceptions (FileError -> OSError, any other Error -> ValueError, same one-line message).

#include "bindings.hpp"
#include "ellreloc/error.hpp"

PYBIND11_MODULE(_ellreloc, m) {
  namespace py = pybind11;
  using namespace ellreloc::python;
  m.doc() = "Object-based camera relocalization with ellipses and ellipsoids (C++ core).";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ellreloc::FileError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const ellreloc::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  bindCore(m);
  bindData(m);
  bindObserve(m);
  bindPose(m);
  bindMapping(m);
  bindIo(m);
  py::module_ sim = m.def_submodule("sim", "Synthetic scenes, rendering and noise, for data with known answers.");
  bindSim(sim);
}
