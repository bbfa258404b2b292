// The pieces of the Python module mmvk (module.cpp puts them together):
// each bind_* adds its classes and functions to the module.
#pragma once

#include <pybind11/pybind11.h>

namespace mmvk::python {

void bind_database(pybind11::module_& m);  // Database, Animation, build()
void bind_search(pybind11::module_& m);    // Search, backends()
void bind_crowd(pybind11::module_& m);     // Crowd

}  // namespace mmvk::python
