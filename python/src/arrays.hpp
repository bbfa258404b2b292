// NumPy arrays in and out. Out: views of memory the library already holds
// (no copy), read-only, each keeping its owner (the Database) alive. In:
// float32 arrays checked for dtype and shape before the library sees them;
// nothing is converted silently, so a float64 array is an error that says so.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace mmvk::python {

// A read-only view of `data` with `shape` (C order) that keeps `owner` alive.
template <class T>
pybind11::array view(pybind11::handle owner, const T* data, std::vector<pybind11::ssize_t> shape) {
  pybind11::array array(pybind11::dtype::of<T>(), std::move(shape), {}, data, owner);
  array.attr("setflags")(pybind11::arg("write") = false);
  return array;
}

// A float32 matrix of `cols` columns: rows x cols values, C-contiguous (a
// strided float32 array is copied; the copy is kept in `keep`). `what`
// names the argument in errors ("queries: expected float32, got float64").
// A 1-D array of `cols` values is one row when `allow_vector`.
struct FloatRows {
  std::span<const float> values;  // [rows x cols]
  std::size_t rows = 0;
  pybind11::array keep;
};
FloatRows float_rows(const pybind11::handle& value, std::size_t cols, const char* what, bool allow_vector = true);

// A float32 vector of exactly `size` values.
std::span<const float> float_vector(const pybind11::handle& value, std::size_t size, const char* what,
                                    pybind11::array& keep);

}  // namespace mmvk::python
