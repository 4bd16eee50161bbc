// The `panoptes._panoptes` extension module: exceptions and the three bound classes.
#include <pybind11/pybind11.h>

#include "core/error.hpp"
#include "core/version.hpp"
#include "python/bindings.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_panoptes, m) {
  m.doc() = "Panoptes movie databases, player engine and in-situ sessions (compiled part)";
  // Library errors keep the message the command line prints after "panoptes: error: ". pybind11
  // tries translators newest first, so FileError (more specific) is registered after Error.
  static py::exception<panoptes::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<panoptes::FileError> file_error(m, "FileError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const panoptes::FileError& e) {
      PyErr_SetString(file_error.ptr(), e.what());
    } catch (const panoptes::Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });
  m.attr("__version__") = panoptes::kVersion;  // CMake project(VERSION), core/version.hpp
  panoptes::python::bind_database(m);
  panoptes::python::bind_player(m);
  panoptes::python::bind_session(m);
#ifdef PANOPTES_HAVE_MPI
  m.attr("with_mpi") = true;
#else
  m.attr("with_mpi") = false;
#endif
}
