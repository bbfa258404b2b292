#include "mmvk/query/query_builder.hpp"

#include <algorithm>
#include <cmath>

namespace mmvk {

namespace {

bool same_layout(const FeatureSchema& a, const FeatureSchema& b) {
  if (a.channels.size() != b.channels.size()) return false;
  for (std::size_t c = 0; c < a.channels.size(); ++c) {
    if (a.channels[c].name != b.channels[c].name || a.channels[c].dims() != b.channels[c].dims()) return false;
  }
  return true;
}

}  // namespace

QueryBuilder::QueryBuilder(FeatureSchema schema)
    : schema_(std::move(schema)), raw_(schema_.dims(), 0.0f), set_(schema_.channels.size(), false) {}

QueryBuilder::QueryBuilder(const Database& database) : QueryBuilder(database.schema()) { database_ = &database; }

Status QueryBuilder::set(std::string_view channel, std::span<const float> values) {
  Result<std::size_t> index = schema_.find_channel(channel, "query");
  if (!index) return index.status();
  return set(*index, values);
}

Status QueryBuilder::set(std::size_t channel_index, std::span<const float> values) {
  if (channel_index >= schema_.channels.size()) {
    return make_error("query: channel index " + std::to_string(channel_index) + " is out of range (" +
                      std::to_string(schema_.channels.size()) + " channels)");
  }
  const FeatureChannel& channel = schema_.channels[channel_index];
  if (values.size() != channel.dims()) {
    return make_error("query: channel '" + channel.name + "' expects " + std::to_string(channel.dims()) +
                      " values, got " + std::to_string(values.size()));
  }
  const std::uint32_t offset = schema_.offset(channel_index);
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return make_error("query: channel '" + channel.name + "' value " + std::to_string(i) + " (" +
                        schema_.dim_name(offset + static_cast<std::uint32_t>(i)) + ") is not finite");
    }
  }
  std::copy(values.begin(), values.end(), raw_.begin() + offset);
  set_[channel_index] = true;
  return {};
}

Status QueryBuilder::check_complete() const {
  std::string missing;
  for (std::size_t c = 0; c < schema_.channels.size(); ++c) {
    if (set_[c]) continue;
    if (!missing.empty()) missing += ", ";
    missing += schema_.channels[c].name;
  }
  if (missing.empty()) return {};
  return make_error("query: channels not set: " + missing);
}

void QueryBuilder::clear() {
  std::fill(raw_.begin(), raw_.end(), 0.0f);
  std::fill(set_.begin(), set_.end(), false);
}

Result<std::vector<float>> QueryBuilder::normalized() const {
  if (database_ == nullptr) {
    return make_error("query: this builder was made from a schema, not a database; use normalize(database, out)");
  }
  std::vector<float> out(raw_.size());
  database_->normalize(raw_, out);
  return out;
}

Status QueryBuilder::normalize(const Database& database, std::span<float> out) const {
  if (!same_layout(schema_, database.schema())) {
    return make_error("query: the database's schema (" + database.schema().channel_names() +
                      ") does not match the query's (" + schema_.channel_names() + ")");
  }
  if (out.size() != raw_.size()) {
    return make_error("query: output has " + std::to_string(out.size()) + " values, expected " +
                      std::to_string(raw_.size()));
  }
  database.normalize(raw_, out);
  return {};
}

}  // namespace mmvk
