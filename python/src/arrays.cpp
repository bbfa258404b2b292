#include "arrays.hpp"

#include "errors.hpp"

namespace mmvk::python {

namespace py = pybind11;

namespace {

std::string shape_text(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) text += (d ? ", " : "") + std::to_string(a.shape(d));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

py::array float32_array(const py::handle& value, const char* what) {
  if (!py::isinstance<py::array>(value)) {
    raise(std::string(what) + ": expected a numpy float32 array, got " +
          std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  auto a = py::reinterpret_borrow<py::array>(value);
  // Equal, not the same object: a float32 dtype carrying metadata is a
  // dtype of its own ("expected a float32 array, got float32"); a
  // byte-swapped one is not equal and is refused.
  if (!a.dtype().equal(py::dtype::of<float>())) {
    raise(std::string(what) + ": expected a float32 array, got " + std::string(py::str(a.dtype())) +
          " (convert with .astype(numpy.float32))");
  }
  // A strided view is copied once into C order; a C-contiguous one is used as it is.
  return py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
}

}  // namespace

FloatRows float_rows(const py::handle& value, std::size_t cols, const char* what, bool allow_vector) {
  FloatRows out;
  out.keep = float32_array(value, what);
  const py::array& a = out.keep;
  const bool vector = allow_vector && a.ndim() == 1;
  if (!(a.ndim() == 2 || vector) || std::size_t(a.shape(a.ndim() - 1)) != cols) {
    raise(std::string(what) + ": expected shape (B, " + std::to_string(cols) + ")" +
          (allow_vector ? " or (" + std::to_string(cols) + ",)" : std::string()) + ", got " + shape_text(a));
  }
  out.rows = vector ? 1 : std::size_t(a.shape(0));
  out.values = {static_cast<const float*>(a.data()), out.rows * cols};
  return out;
}

std::span<const float> float_vector(const py::handle& value, std::size_t size, const char* what, py::array& keep) {
  keep = float32_array(value, what);
  if (keep.ndim() != 1 || std::size_t(keep.shape(0)) != size) {
    raise(std::string(what) + ": expected shape (" + std::to_string(size) + ",), got " + shape_text(keep));
  }
  return {static_cast<const float*>(keep.data()), size};
}

}  // namespace mmvk::python
