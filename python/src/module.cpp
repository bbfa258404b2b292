// The Python module mmvk: motion matching search (and a crowd to steer) with
// NumPy arrays in and out. docs/python.md describes it; mmvk.pyi types it.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(mmvk, m) {
  m.doc() =
      "mmvk: motion matching search for crowds, on Vulkan.\n\n"
      "  db = mmvk.build('walks/', fps=30)            # or mmvk.Database.load('walks.mmdb')\n"
      "  search = mmvk.Search(db, backend='clusters')\n"
      "  frames, costs = search.search(db.features[:8], k=4)\n"
      "  crowd = mmvk.Crowd(db, agents=100); crowd.step()\n\n"
      "Errors raise ValueError (bad input) or OSError (files) with the library's message.";
  m.attr("__version__") = MMVK_VERSION_STRING;
  mmvk::python::bind_database(m);
  mmvk::python::bind_search(m);
  mmvk::python::bind_crowd(m);
}
