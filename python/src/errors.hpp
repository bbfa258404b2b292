// Library errors as Python exceptions: the library's message as it is, as a
// ValueError (bad input: arrays, names, options, file contents) or an
// OSError (a file that cannot be found, read or written).
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <type_traits>
#include <string>
#include <utility>

#include <pybind11/pybind11.h>

#include "mmvk/common/status.hpp"

namespace mmvk::python {

enum class ErrorKind { Value, OS };

// Throws the Python exception (the GIL must be held).
[[noreturn]] void raise(const std::string& message, ErrorKind kind = ErrorKind::Value);

inline void check(const Status& status, ErrorKind kind = ErrorKind::Value) {
  if (!status.ok()) raise(status.message(), kind);
}

template <class T>
T take(Result<T>&& result, ErrorKind kind = ErrorKind::Value) {
  if (!result.ok()) raise(result.message(), kind);
  return std::move(result).value();
}

// OS when `path` names nothing (or cannot be looked at), else Value: a
// missing input is an OSError, a malformed one a ValueError.
ErrorKind kind_for_input(const std::filesystem::path& path);

// A str or os.PathLike as a path (ValueError otherwise, and for a path
// that holds a NUL byte); a name that is not UTF-8 is kept as its bytes.
std::filesystem::path to_path(const pybind11::handle& value, const char* what);

// Arguments as C++ numbers, with errors that name them instead of pybind11's
// "Unable to cast Python instance to C++ type": a TypeError for a value of
// the wrong type ("threads: expected an integer, got str"), a ValueError for
// one out of range ("threads: expected an integer from 0 to 4294967295, got
// -1"). Integers take anything with __index__ (NumPy's integers too).
std::int64_t integer_argument(const pybind11::handle& value, const std::string& what, std::int64_t min, std::int64_t max);
std::uint64_t unsigned_argument(const pybind11::handle& value, const std::string& what, std::uint64_t max);
// A finite number that fits a float (ints, floats, NumPy scalars).
float float_argument(const pybind11::handle& value, const std::string& what);

template <class T>
T integer_as(const pybind11::handle& value, const std::string& what) {
  if constexpr (std::is_signed_v<T>) {
    return T(integer_argument(value, what, std::numeric_limits<T>::min(), std::numeric_limits<T>::max()));
  } else {
    return T(unsigned_argument(value, what, std::numeric_limits<T>::max()));
  }
}

}  // namespace mmvk::python
