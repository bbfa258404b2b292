#include "errors.hpp"

#include <Python.h>

namespace mmvk::python {

namespace py = pybind11;

void raise(const std::string& message, ErrorKind kind) {
  if (kind == ErrorKind::OS) {
    PyErr_SetString(PyExc_OSError, message.c_str());
    throw py::error_already_set();
  }
  throw py::value_error(message);
}

ErrorKind kind_for_input(const std::filesystem::path& path) {
  std::error_code ec;
  const bool exists = std::filesystem::exists(path, ec);
  return exists && !ec ? ErrorKind::Value : ErrorKind::OS;
}

std::filesystem::path to_path(const py::handle& value, const char* what) {
  if (!py::isinstance<py::str>(value) && !py::hasattr(value, "__fspath__")) {
    raise(std::string(what) + ": expected a path (str or os.PathLike), got " +
          std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  return std::filesystem::path(py::str(py::module_::import("os").attr("fspath")(value)).cast<std::string>());
}

}  // namespace mmvk::python
