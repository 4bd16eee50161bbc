#pragma once
// The pieces of the `panoptes._panoptes` extension module (pybind11); the pure-Python package
// src/python/panoptes/ wraps them into the public API.
#include <pybind11/pybind11.h>

namespace panoptes::python {

/// `Database`: an opened movie database, its manifest, cameras as NumPy arrays and decoded frames.
void bind_database(pybind11::module_& m);
/// `Player`: the playback engine, headless, on a virtual clock.
void bind_player(pybind11::module_& m);
/// `Session`: in-situ visualization from a Python simulation (zero-copy fields, mpi4py communicators).
void bind_session(pybind11::module_& m);

}  // namespace panoptes::python
