// Building a ClusterTable from an assignment, and checking that a table
// (possibly loaded from a file) really covers a database: every bound the
// pruned search uses must hold for every member, or pruning stops being exact.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "clusters/cluster_table_build.hpp"
#include "mmvk/common/hash.hpp"

namespace mmvk::detail {

float channel_distance_up(const float* row, const float* centroid, std::uint32_t begin, std::uint32_t end) {
  double sum = 0.0;
  for (std::uint32_t d = begin; d < end; ++d) {
    const double diff = double(row[d]) - double(centroid[d]);
    sum += diff * diff;
  }
  const double distance = std::sqrt(sum);
  // The double result is within ~1e-15 relative of the real distance; the
  // next float above it stays a true upper bound (nearest rounding may go down).
  float up = static_cast<float>(distance);
  if (double(up) <= distance) up = std::nextafter(up, std::numeric_limits<float>::infinity());
  return up;
}

ClusterTable build_cluster_table(const Database& database, std::vector<float> centroids,
                                 const std::vector<std::uint32_t>& frame_cluster) {
  const std::uint32_t frames = database.frame_count();
  const std::uint32_t dims = database.dims();
  const FeatureSchema& schema = database.schema();
  ClusterTable t;
  t.database_hash = database.content_hash();
  t.dims = dims;
  t.cluster_count = static_cast<std::uint32_t>(centroids.size() / dims);
  t.channel_count = static_cast<std::uint32_t>(schema.channels.size());
  t.centroids = std::move(centroids);
  const std::uint32_t k = t.cluster_count;

  // Counting sort by cluster keeps frame ids ascending within each cluster.
  t.offsets.assign(k + 1, 0);
  for (std::uint32_t f = 0; f < frames; ++f) ++t.offsets[frame_cluster[f] + 1];
  for (std::uint32_t c = 0; c < k; ++c) t.offsets[c + 1] += t.offsets[c];
  t.members.resize(frames);
  std::vector<std::uint32_t> next(t.offsets.begin(), t.offsets.end() - 1);
  for (std::uint32_t f = 0; f < frames; ++f) t.members[next[frame_cluster[f]]++] = f;

  t.box_min.assign(std::size_t{k} * dims, 0.0f);
  t.box_max.assign(std::size_t{k} * dims, 0.0f);
  t.min_multiplier.assign(k, 1.0f);
  t.min_bias.assign(k, 0.0f);
  t.tag_union.assign(k, 0);
  t.tag_intersection.assign(k, ~TagMask{0});
  t.flags_intersection.assign(k, ~std::uint32_t{0});
  t.channel_radius.assign(std::size_t{k} * t.channel_count, 0.0f);
  for (std::uint32_t c = 0; c < k; ++c) {
    float* lo = t.box_min.data() + std::size_t{c} * dims;
    float* hi = t.box_max.data() + std::size_t{c} * dims;
    const float* centroid = t.centroids.data() + std::size_t{c} * dims;
    if (t.offsets[c] == t.offsets[c + 1]) {
      std::copy_n(centroid, dims, lo);
      std::copy_n(centroid, dims, hi);
      continue;
    }
    std::fill_n(lo, dims, std::numeric_limits<float>::infinity());
    std::fill_n(hi, dims, -std::numeric_limits<float>::infinity());
    float mult = std::numeric_limits<float>::infinity();
    float bias = std::numeric_limits<float>::infinity();
    float* radius = t.channel_radius.data() + std::size_t{c} * t.channel_count;
    for (std::uint32_t m = t.offsets[c]; m < t.offsets[c + 1]; ++m) {
      const std::uint32_t f = t.members[m];
      const float* row = database.row(f).data();
      for (std::uint32_t d = 0; d < dims; ++d) {
        lo[d] = std::min(lo[d], row[d]);
        hi[d] = std::max(hi[d], row[d]);
      }
      mult = std::min(mult, database.frame_multiplier()[f]);
      bias = std::min(bias, database.frame_bias()[f]);
      t.tag_union[c] |= database.frame_tags()[f];
      t.tag_intersection[c] &= database.frame_tags()[f];
      t.flags_intersection[c] &= database.frame_flags()[f];
      std::uint32_t begin = 0;
      for (std::uint32_t ch = 0; ch < t.channel_count; ++ch) {
        const std::uint32_t end = begin + schema.channels[ch].dims();
        radius[ch] = std::max(radius[ch], channel_distance_up(row, centroid, begin, end));
        begin = end;
      }
    }
    t.min_multiplier[c] = mult;
    t.min_bias[c] = bias;
  }
  return t;
}

}  // namespace mmvk::detail

namespace mmvk {

namespace {

std::string size_error(const char* field, std::size_t got, std::size_t expected) {
  return std::string("cluster table: ") + field + " has " + std::to_string(got) + " entries, expected " +
         std::to_string(expected);
}

// The table's identity and the sizes of its arrays against the database.
Status check_shape(const ClusterTable& t, const Database& database) {
  const std::uint32_t frames = database.frame_count();
  const std::uint32_t dims = database.dims();
  const FeatureSchema& schema = database.schema();
  if (t.database_hash != database.content_hash()) {
    return make_error("cluster table: built from another database (database hash " + hash_hex(t.database_hash) +
                      ", this database's is " + hash_hex(database.content_hash()) + ")");
  }
  if (t.dims != dims) {
    return make_error("cluster table: " + std::to_string(t.dims) + " dims, the database has " + std::to_string(dims));
  }
  if (t.members.size() != frames) {
    return make_error("cluster table: covers " + std::to_string(t.members.size()) + " frames, the database has " +
                      std::to_string(frames));
  }
  if (t.channel_count != schema.channels.size()) {
    return make_error("cluster table: " + std::to_string(t.channel_count) + " channels, the database's schema has " +
                      std::to_string(schema.channels.size()));
  }
  const std::uint32_t k = t.cluster_count;
  if (k == 0 || k > std::max<std::uint32_t>(frames, 1)) {
    return make_error("cluster table: cluster_count " + std::to_string(k) + " is out of range [1, " +
                      std::to_string(frames) + "]");
  }
  const std::size_t kd = std::size_t{k} * dims;
  if (t.centroids.size() != kd) return make_error(size_error("centroids", t.centroids.size(), kd));
  if (t.offsets.size() != k + std::size_t{1}) return make_error(size_error("offsets", t.offsets.size(), k + std::size_t{1}));
  if (t.box_min.size() != kd) return make_error(size_error("box_min", t.box_min.size(), kd));
  if (t.box_max.size() != kd) return make_error(size_error("box_max", t.box_max.size(), kd));
  if (t.min_multiplier.size() != k) return make_error(size_error("min_multiplier", t.min_multiplier.size(), k));
  if (t.min_bias.size() != k) return make_error(size_error("min_bias", t.min_bias.size(), k));
  if (t.tag_union.size() != k) return make_error(size_error("tag_union", t.tag_union.size(), k));
  if (t.tag_intersection.size() != k) return make_error(size_error("tag_intersection", t.tag_intersection.size(), k));
  if (t.flags_intersection.size() != k) {
    return make_error(size_error("flags_intersection", t.flags_intersection.size(), k));
  }
  const std::size_t kc = std::size_t{k} * t.channel_count;
  if (t.channel_radius.size() != kc) return make_error(size_error("channel_radius", t.channel_radius.size(), kc));
  return {};
}

// Member frame f of cluster c lies inside the cluster's box and channel
// radii, and within its bounds on modifiers, tags and flags.
Status check_member(const ClusterTable& t, const Database& database, std::uint32_t c, std::uint32_t f,
                    const std::string& member) {
  const std::uint32_t dims = database.dims();
  const FeatureSchema& schema = database.schema();
  const float* lo = t.box_min.data() + std::size_t{c} * dims;
  const float* hi = t.box_max.data() + std::size_t{c} * dims;
  const float* centroid = t.centroids.data() + std::size_t{c} * dims;
  const float* radius = t.channel_radius.data() + std::size_t{c} * t.channel_count;
  const float* row = database.row(f).data();
  for (std::uint32_t d = 0; d < dims; ++d) {
    if (row[d] < lo[d] || row[d] > hi[d]) return make_error(member + " lies outside the box in " + schema.dim_name(d));
  }
  std::uint32_t begin = 0;
  for (std::uint32_t ch = 0; ch < t.channel_count; ++ch) {
    const std::uint32_t end = begin + schema.channels[ch].dims();
    if (!(detail::channel_distance_up(row, centroid, begin, end) <= radius[ch])) {
      return make_error(member + " lies outside the radius of channel '" + schema.channels[ch].name + "'");
    }
    begin = end;
  }
  if (!(database.frame_multiplier()[f] >= t.min_multiplier[c])) return make_error(member + " has a multiplier below min_multiplier");
  if (!(database.frame_bias()[f] >= t.min_bias[c])) return make_error(member + " has a bias below min_bias");
  if ((database.frame_tags()[f] & ~t.tag_union[c]) != 0) return make_error(member + " has tags outside tag_union");
  if ((t.tag_intersection[c] & ~database.frame_tags()[f]) != 0) return make_error(member + " lacks a tag of tag_intersection");
  if ((t.flags_intersection[c] & ~database.frame_flags()[f]) != 0) {
    return make_error(member + " lacks a flag of flags_intersection");
  }
  return {};
}

}  // namespace

Status validate_cluster_table(const ClusterTable& t, const Database& database) {
  MMVK_TRY(check_shape(t, database));
  const std::uint32_t frames = database.frame_count();
  const std::uint32_t dims = database.dims();
  const std::uint32_t k = t.cluster_count;
  for (std::size_t i = 0; i < std::size_t{k} * dims; ++i) {
    if (!std::isfinite(t.centroids[i]) || !std::isfinite(t.box_min[i]) || !std::isfinite(t.box_max[i])) {
      return make_error("cluster table: cluster " + std::to_string(i / dims) + " has a non-finite centroid or box");
    }
  }
  if (t.offsets[0] != 0 || t.offsets[k] != frames) {
    return make_error("cluster table: offsets must run from 0 to the frame count " + std::to_string(frames));
  }
  // Every frame in exactly one cluster, each cluster's members ascending.
  std::vector<bool> seen(frames, false);
  for (std::uint32_t c = 0; c < k; ++c) {
    const std::string where = "cluster table: cluster " + std::to_string(c);
    if (t.offsets[c] > t.offsets[c + 1]) return make_error(where + ": offsets decrease");
    for (std::uint32_t m = t.offsets[c]; m < t.offsets[c + 1]; ++m) {
      const std::uint32_t f = t.members[m];
      if (f >= frames) return make_error(where + ": member frame " + std::to_string(f) + " is out of range");
      if (seen[f]) return make_error(where + ": frame " + std::to_string(f) + " is in more than one cluster");
      seen[f] = true;
      if (m > t.offsets[c] && t.members[m - 1] >= f) return make_error(where + ": members are not in ascending order");
      MMVK_TRY(check_member(t, database, c, f, where + ": member frame " + std::to_string(f)));
    }
  }
  return {};
}

}  // namespace mmvk
