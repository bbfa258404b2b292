// Library errors as Python exceptions: the library's message as it is, as a
// ValueError (bad input: arrays, names, options, file contents) or an
// OSError (a file that cannot be found, read or written).
#pragma once

#include <filesystem>
#include <string>
#include <utility>

#include <pybind11/pybind11.h>

#include "mmvk/status.hpp"

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

// A str or os.PathLike as a path (ValueError otherwise).
std::filesystem::path to_path(const pybind11::handle& value, const char* what);

}  // namespace mmvk::python
