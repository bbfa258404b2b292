#include "common/json_parse.hpp"

#include "mmvk/json_check.hpp"

#include <cmath>
#include <set>
#include <vector>

namespace mmvk::detail {

Result<nlohmann::json> parse_json_text(std::string_view text, const std::string& source) {
  using Json = nlohmann::json;
  // nlohmann's lexer reads a NUL byte as the end of the input, which would
  // accept anything after one; JSON text holds none (control characters in
  // strings are escaped).
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    return make_error(source + ": a NUL byte at offset " + std::to_string(nul) + " (not JSON text)");
  }
  // The keys seen so far in each object being parsed, innermost last.
  std::vector<std::set<std::string>> open_objects;
  std::string duplicate;
  const Json::parser_callback_t track = [&](int, Json::parse_event_t event, Json& parsed) {
    if (event == Json::parse_event_t::object_start) {
      open_objects.emplace_back();
    } else if (event == Json::parse_event_t::object_end) {
      if (!open_objects.empty()) open_objects.pop_back();
    } else if (event == Json::parse_event_t::key && !open_objects.empty() && parsed.is_string()) {
      const std::string& key = parsed.get_ref<const std::string&>();
      if (!open_objects.back().insert(key).second && duplicate.empty()) duplicate = key;
    }
    return true;
  };
  Json root = Json::parse(text, track, /*allow_exceptions=*/false);
  if (root.is_discarded()) return make_error(source + ": not valid JSON");
  if (!duplicate.empty()) return make_error(source + ": duplicate key \"" + duplicate + "\"");
  return root;
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
