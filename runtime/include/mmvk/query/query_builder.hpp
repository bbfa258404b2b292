// Builds a query's feature vector from the schema by channel name, so no
// layout offset is written by hand: the same FeatureSchema that laid out the
// database rows lays out the query.
//
//   QueryBuilder builder(database);
//   MMVK_TRY(builder.set("trajectory_position", positions));  // raw units (metres)
//   Result<std::vector<float>> query = builder.normalized();   // database's offsets and scales
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

class QueryBuilder {
 public:
  // For raw vectors only (normalized() then needs a database).
  explicit QueryBuilder(FeatureSchema schema);
  // Raw vectors laid out by the database's schema, normalized with its
  // offsets and scales. `database` must outlive the builder.
  explicit QueryBuilder(const Database& database);

  const FeatureSchema& schema() const { return schema_; }
  std::uint32_t dims() const { return static_cast<std::uint32_t>(raw_.size()); }

  // Sets a channel's raw values, in the channel's own layout and units
  // (e.g. trajectory_position: x, z per future offset, metres). The error
  // names the channel and the number of values it expects, or the unknown
  // name and the schema's channels, or the value that is not finite.
  Status set(std::string_view channel, std::span<const float> values);
  Status set(std::size_t channel_index, std::span<const float> values);

  // Channels not set since construction or clear() hold raw zeros.
  bool is_set(std::size_t channel_index) const { return set_[channel_index]; }
  // Error naming every channel not set yet; success when all are.
  Status check_complete() const;
  void clear();

  // The raw vector [dims], schema order.
  std::span<const float> raw() const { return raw_; }

  // The normalized vector [dims], ready for QueryBatch::features; an error
  // when the builder was made from a schema alone (use normalize()).
  Result<std::vector<float>> normalized() const;
  // Normalizes with `database`'s offsets and scales into out[dims]; the
  // error says when its schema does not match the builder's.
  Status normalize(const Database& database, std::span<float> out) const;

 private:
  FeatureSchema schema_;
  const Database* database_ = nullptr;
  std::vector<float> raw_;
  std::vector<bool> set_;
};

}  // namespace mmvk
