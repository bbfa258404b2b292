#include "errors.hpp"

#include <Python.h>

#include <cmath>

namespace mmvk::python {

namespace py = pybind11;

void raise(const std::string& message, ErrorKind kind) {
  // A message may quote a path that is not UTF-8: its bytes are shown as
  // \xHH escapes instead of the message failing to decode.
  PyObject* text = PyUnicode_DecodeUTF8(message.data(), py::ssize_t(message.size()), "backslashreplace");
  if (text == nullptr) throw py::error_already_set();
  PyErr_SetObject(kind == ErrorKind::OS ? PyExc_OSError : PyExc_ValueError, text);
  Py_DECREF(text);
  throw py::error_already_set();
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
  // os.fsencode gives the bytes the OS takes: a name that is not UTF-8 (read
  // from a directory listing as surrogate escapes) reaches the file as it is.
  const std::string bytes = py::bytes(py::module_::import("os").attr("fsencode")(value));
  // The OS would read the path only up to a NUL: 'db.mmdb\0junk' would load
  // db.mmdb.
  if (const std::size_t nul = bytes.find('\0'); nul != std::string::npos) {
    raise(std::string(what) + ": the path holds a NUL byte at offset " + std::to_string(nul));
  }
  return std::filesystem::path(bytes);
}

namespace {

std::string type_name(const py::handle& value) { return py::str(py::type::of(value).attr("__name__")); }

// The value as a Python int (operator.index), or a TypeError naming `what`.
py::object index_of(const py::handle& value, const std::string& what) {
  PyObject* index = PyIndex_Check(value.ptr()) ? PyNumber_Index(value.ptr()) : nullptr;
  if (index == nullptr) {
    PyErr_Clear();
    throw py::type_error(what + ": expected an integer, got " + type_name(value));
  }
  return py::reinterpret_steal<py::object>(index);
}

// `index` in [min, max] (Python ints, compared without overflow), else a
// ValueError naming `what` and the range.
void check_range(const py::object& index, const std::string& what, const py::object& min, const py::object& max) {
  if (PyObject_RichCompareBool(index.ptr(), min.ptr(), Py_LT) == 1 ||
      PyObject_RichCompareBool(index.ptr(), max.ptr(), Py_GT) == 1) {
    throw py::value_error(what + ": expected an integer from " + std::string(py::str(min)) + " to " +
                          std::string(py::str(max)) + ", got " + std::string(py::str(index)));
  }
}

}  // namespace

std::int64_t integer_argument(const py::handle& value, const std::string& what, std::int64_t min, std::int64_t max) {
  const py::object index = index_of(value, what);
  check_range(index, what, py::int_(min), py::int_(max));
  return index.cast<std::int64_t>();
}

std::uint64_t unsigned_argument(const py::handle& value, const std::string& what, std::uint64_t max) {
  const py::object index = index_of(value, what);
  check_range(index, what, py::int_(0), py::int_(max));
  return index.cast<std::uint64_t>();
}

float float_argument(const py::handle& value, const std::string& what) {
  // PyNumber_Float would also read a str ("1.5"); a number is asked for.
  const bool number = PyFloat_Check(value.ptr()) || PyIndex_Check(value.ptr()) ||
                      (!py::isinstance<py::str>(value) && !py::isinstance<py::bytes>(value) &&
                       py::hasattr(value, "__float__"));
  if (!number) throw py::type_error(what + ": expected a number, got " + type_name(value));
  const double number_value = PyFloat_AsDouble(value.ptr());
  if (number_value == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();  // an int beyond double's range
    throw py::value_error(what + ": not a finite number");
  }
  if (!std::isfinite(number_value) || std::abs(number_value) > 3.0e38) {
    throw py::value_error(what + ": expected a finite number within float's range, got " + std::string(py::str(value)));
  }
  return float(number_value);
}

}  // namespace mmvk::python
