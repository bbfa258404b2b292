#include "search/cluster_groups.hpp"

#include <algorithm>
#include <limits>

namespace mmvk::detail {

namespace {

void split(const ClusterTable& t, std::uint32_t group_size, std::uint32_t* first, std::uint32_t* last) {
  const std::size_t n = static_cast<std::size_t>(last - first);
  if (n <= group_size) return;
  std::uint32_t widest = 0;
  float widest_spread = -1.0f;
  for (std::uint32_t d = 0; d < t.dims; ++d) {
    float lo = std::numeric_limits<float>::infinity();
    float hi = -lo;
    for (const std::uint32_t* c = first; c != last; ++c) {
      lo = std::min(lo, t.centroids[std::size_t{*c} * t.dims + d]);
      hi = std::max(hi, t.centroids[std::size_t{*c} * t.dims + d]);
    }
    if (hi - lo > widest_spread) {
      widest_spread = hi - lo;
      widest = d;
    }
  }
  // The multiple of group_size nearest to half; n > group_size, so the split
  // lies strictly inside.
  const std::size_t half = std::max<std::size_t>(group_size, (n / 2 + group_size / 2) / group_size * group_size);
  const auto key = [&](std::uint32_t a, std::uint32_t b) {
    const float va = t.centroids[std::size_t{a} * t.dims + widest];
    const float vb = t.centroids[std::size_t{b} * t.dims + widest];
    return va < vb || (va == vb && a < b);
  };
  std::nth_element(first, first + half, last, key);
  split(t, group_size, first, first + half);
  split(t, group_size, first + half, last);
}

}  // namespace

std::vector<std::uint32_t> group_order(const ClusterTable& table, std::uint32_t group_size) {
  std::vector<std::uint32_t> order(table.cluster_count);
  for (std::uint32_t c = 0; c < table.cluster_count; ++c) order[c] = c;
  split(table, group_size, order.data(), order.data() + order.size());
  return order;
}

ClusterTable reorder_clusters(const ClusterTable& t, std::span<const std::uint32_t> order) {
  ClusterTable r;
  r.database_hash = t.database_hash;
  r.dims = t.dims;
  r.cluster_count = t.cluster_count;
  r.channel_count = t.channel_count;
  r.offsets.push_back(0);
  for (const std::uint32_t c : order) {
    r.members.insert(r.members.end(), t.members.begin() + t.offsets[c], t.members.begin() + t.offsets[c + 1]);
    r.offsets.push_back(static_cast<std::uint32_t>(r.members.size()));
  }
  const auto per_cluster = [&](const auto& from, auto& to, std::size_t width) {
    if (from.empty()) return;  // an optional field the table does not carry
    to.reserve(from.size());
    for (const std::uint32_t c : order) {
      to.insert(to.end(), from.begin() + std::ptrdiff_t(c * width), from.begin() + std::ptrdiff_t((c + 1) * width));
    }
  };
  per_cluster(t.centroids, r.centroids, t.dims);
  per_cluster(t.box_min, r.box_min, t.dims);
  per_cluster(t.box_max, r.box_max, t.dims);
  per_cluster(t.min_multiplier, r.min_multiplier, 1);
  per_cluster(t.min_bias, r.min_bias, 1);
  per_cluster(t.tag_union, r.tag_union, 1);
  per_cluster(t.flags_intersection, r.flags_intersection, 1);
  per_cluster(t.tag_intersection, r.tag_intersection, 1);
  per_cluster(t.channel_radius, r.channel_radius, t.channel_count);
  return r;
}

}  // namespace mmvk::detail
