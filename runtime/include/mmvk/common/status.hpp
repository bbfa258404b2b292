// Error handling at the library boundary: every public call that can fail
// returns a Status or a Result<T> carrying a human-readable message that names
// the file, line, field or parameter at fault. The library never throws,
// exits or aborts on bad input; it asserts only on its own invariants.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace mmvk {

struct Error {
  std::string message;
};

class [[nodiscard]] Status {
 public:
  Status() = default;  // success
  Status(Error error) : error_(std::move(error)) {}

  static Status success() { return {}; }

  bool ok() const { return !error_.has_value(); }
  explicit operator bool() const { return ok(); }
  // Precondition: !ok().
  const Error& error() const { return *error_; }
  const std::string& message() const { return error_->message; }

 private:
  std::optional<Error> error_;
};

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}
  Result(Error error) : state_(std::in_place_index<1>, std::move(error)) {}
  // Lets `return status;` forward a failed Status. Precondition: !status.ok().
  Result(const Status& status) : state_(std::in_place_index<1>, status.error()) {}

  bool ok() const { return state_.index() == 0; }
  explicit operator bool() const { return ok(); }

  // Preconditions: ok() for value access, !ok() for error().
  T& value() & { return std::get<0>(state_); }
  const T& value() const& { return std::get<0>(state_); }
  T&& value() && { return std::get<0>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  const Error& error() const { return std::get<1>(state_); }
  const std::string& message() const { return error().message; }
  Status status() const { return ok() ? Status{} : Status{error()}; }

 private:
  std::variant<T, Error> state_;
};

inline Error make_error(std::string message) { return Error{std::move(message)}; }

}  // namespace mmvk

// Returns early from the enclosing function with the error of a failed
// Status-returning expression.
#define MMVK_TRY(expr)                          \
  do {                                          \
    ::mmvk::Status mmvk_try_status_ = (expr);   \
    if (!mmvk_try_status_.ok()) return mmvk_try_status_.error(); \
  } while (false)

// Evaluates a Result-returning expression; on failure returns its error from
// the enclosing function, otherwise moves the value into `lhs`, which may be
// a declaration:  MMVK_ASSIGN_OR_RETURN(auto database, load_database(path));
#define MMVK_ASSIGN_OR_RETURN(lhs, expr) \
  MMVK_ASSIGN_OR_RETURN_IMPL_(MMVK_CONCAT_(mmvk_result_, __LINE__), lhs, expr)
#define MMVK_ASSIGN_OR_RETURN_IMPL_(result, lhs, expr) \
  auto result = (expr);                                \
  if (!result.ok()) return result.error();             \
  lhs = std::move(result).value()
#define MMVK_CONCAT_(a, b) MMVK_CONCAT_INNER_(a, b)
#define MMVK_CONCAT_INNER_(a, b) a##b
