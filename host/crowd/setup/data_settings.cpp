#include "setup/data_settings.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

#include "mmvk/common/json_check.hpp"
#include "mmvk/common/number_text.hpp"

namespace mmvk::crowd {

namespace {

using Json = nlohmann::json;

constexpr const char* kKeys[] = {"correction_half_life", "continuing_bias", "continuing_multiplier",
                                 "exclusion_window"};

Result<float> read_number(const Json& value, const std::string& where) {
  if (!value.is_number()) return make_error(where + ": expected a number");
  const double number = value.get<double>();
  if (!std::isfinite(number) || std::fabs(number) > 3.0e38) return make_error(where + ": expected a finite number");
  return float(number);
}

Status read_setting(const std::string& key, const Json& value, const std::string& where, DataSettings& out) {
  if (key == "exclusion_window") {
    if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 0xFFFFFFFFu) {
      return make_error(where + ": expected an integer number of frames >= 0");
    }
    out.exclusion_window = value.get<std::uint32_t>();
    return {};
  }
  MMVK_ASSIGN_OR_RETURN(const float number, read_number(value, where));
  if (key == "correction_half_life") {
    if (!(number > 0.0f)) return make_error(where + ": expected a positive number of seconds");
    out.correction_half_life = number;
  } else if (key == "continuing_bias") {
    out.continuing_bias = number;
  } else {
    if (number < 0.0f) return make_error(where + ": expected a number >= 0");
    out.continuing_multiplier = number;
  }
  return {};
}

}  // namespace

std::string data_setting_keys() {
  std::string keys;
  for (const char* key : kKeys) keys += (keys.empty() ? "" : ", ") + std::string(key);
  return keys;
}

Result<DataSettings> parse_data_settings(std::string_view json, const std::string& source) {
  DataSettings out;
  if (json.empty()) return out;
  MMVK_TRY(check_json_text(json, source + ": crowd"));
  const Json block = Json::parse(json, nullptr, false);
  if (block.is_discarded() || !block.is_object()) return make_error(source + ": crowd: expected an object");
  for (const auto& item : block.items()) {
    const std::string where = source + ": crowd." + item.key();
    bool known = false;
    for (const char* key : kKeys) known = known || item.key() == key;
    if (!known) return make_error(where + ": unknown crowd setting (known: " + data_setting_keys() + ")");
    MMVK_TRY(read_setting(item.key(), item.value(), where, out));
  }
  return out;
}

Result<DataSettings> data_settings(const Database& database, const std::string& source) {
  return parse_data_settings(database.crowd_settings(), source);
}

std::string describe_data_settings(const DataSettings& s) {
  std::string out;
  auto add = [&out](const char* flag, const std::string& value) {
    out += (out.empty() ? "--" : ", --") + std::string(flag) + " " + value;
  };
  if (s.correction_half_life) add("correction-half-life", number_text(*s.correction_half_life));
  if (s.continuing_bias) add("continuing-bias", number_text(*s.continuing_bias));
  if (s.continuing_multiplier) add("continuing-multiplier", number_text(*s.continuing_multiplier));
  if (s.exclusion_window) add("exclusion-window", std::to_string(*s.exclusion_window));
  return out;
}

}  // namespace mmvk::crowd
