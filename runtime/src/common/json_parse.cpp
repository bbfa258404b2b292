#include "common/json_parse.hpp"

#include "mmvk/common/input_text.hpp"
#include "mmvk/common/json_check.hpp"

#include <cmath>
#include <utility>
#include <vector>

namespace mmvk::detail {

namespace {

using Json = nlohmann::json;

// Builds the document as nlohmann's own DOM parser does, with the checks
// made as it goes. nlohmann's callback parser would do the key check too,
// but its end of every object scans the enclosing array for discarded
// values, which is quadratic in an array of objects (a 46 MB scenario took
// minutes); this handler's every event is constant time but the key
// lookup (logarithmic).
class StrictJsonHandler {
 public:
  bool null() { return add(Json(nullptr)) != nullptr; }
  bool boolean(bool value) { return add(Json(value)) != nullptr; }
  bool number_integer(Json::number_integer_t value) { return add(Json(value)) != nullptr; }
  bool number_unsigned(Json::number_unsigned_t value) { return add(Json(value)) != nullptr; }
  bool number_float(Json::number_float_t value, const std::string&) { return add(Json(value)) != nullptr; }
  bool string(std::string& value) { return add(Json(std::move(value))) != nullptr; }
  bool binary(Json::binary_t& value) { return add(Json(std::move(value))) != nullptr; }
  bool start_object(std::size_t) { return open(Json::object()); }
  bool start_array(std::size_t) { return open(Json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(std::string& key) {
    // The innermost open value is the object this key belongs to.
    if (open_.back()->contains(key)) {
      error_ = "duplicate key " + quoted_text(key);
      return false;
    }
    key_ = std::move(key);
    return true;
  }

  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception& failure) {
    error_ = "not valid JSON at byte " + std::to_string(position > 0 ? position - 1 : 0) + ": " +
             printable_text(reason(failure.what()), 160);
    return false;
  }

  const std::string& error() const { return error_; }
  Json take() { return std::move(root_); }

 private:
  // nlohmann's what() is "[json.exception.parse_error.101] parse error at
  // line 1, column 5: syntax error ..."; the byte offset says where, so the
  // reason is the text after the position.
  static std::string reason(std::string_view what) {
    if (const std::size_t tag = what.find("] "); tag != std::string_view::npos) what.remove_prefix(tag + 2);
    if (what.starts_with("parse error")) {
      if (const std::size_t colon = what.find(": "); colon != std::string_view::npos) what.remove_prefix(colon + 2);
    }
    return std::string(what);
  }

  // Puts `value` where the parser is (the root, the open array's end or the
  // open object's last key) and returns where it now lives.
  Json* add(Json value) {
    if (open_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    Json& parent = *open_.back();
    if (parent.is_array()) {
      parent.push_back(std::move(value));
      return &parent.back();
    }
    Json& slot = parent[key_];
    slot = std::move(value);
    return &slot;
  }

  // A pointer to the open value stays valid: nothing is added to its parent
  // until it closes (std::map nodes and the array's last element).
  bool open(Json value) {
    if (open_.size() >= kMaxJsonDepth) {
      error_ = "arrays and objects nested more than " + std::to_string(kMaxJsonDepth) + " levels deep";
      return false;
    }
    open_.push_back(add(std::move(value)));
    return true;
  }

  bool close() {
    open_.pop_back();
    return true;
  }

  Json root_;
  std::vector<Json*> open_;  // the arrays and objects being parsed, innermost last
  std::string key_;          // the open object's key whose value comes next
  std::string error_;
};

}  // namespace

Result<nlohmann::json> parse_json_text(std::string_view text, const std::string& source) {
  // nlohmann's lexer reads a NUL byte as the end of the input, which would
  // accept anything after one; JSON text holds none (control characters in
  // strings are escaped).
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    return make_error(source + ": a NUL byte at offset " + std::to_string(nul) + " (not JSON text)");
  }
  StrictJsonHandler handler;
  // strict: bytes after the value are a syntax error ("expected end of input").
  if (!Json::sax_parse(text, &handler, Json::input_format_t::json, /*strict=*/true)) {
    return make_error(source + ": " + handler.error());
  }
  return handler.take();
}

Result<float> json_float(const nlohmann::json& value, const std::string& where) {
  if (!value.is_number()) return make_error(where + ": expected a number");
  const double number = value.get<double>();
  if (!std::isfinite(number) || std::abs(number) > 3.0e38) return make_error(where + ": not a finite number");
  return static_cast<float>(number);
}

}  // namespace mmvk::detail

namespace mmvk {

Status check_json_text(std::string_view text, std::string_view source) {
  return detail::parse_json_text(text, std::string(source)).status();
}

}  // namespace mmvk
