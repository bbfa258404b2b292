// The order of a ClusterTable's clusters that the cluster search's group
// level needs (runs of nearby centroids), and the table in that order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/clusters/cluster_table.hpp"

namespace mmvk::detail {

// [clusters]: the table's cluster ids in an order where every run of
// `group_size` (from the first) holds nearby centroids: a k-d split on the
// centroids' widest dimension at a multiple of group_size, recursively
// (ties: the lower id first). Deterministic.
std::vector<std::uint32_t> group_order(const ClusterTable& table, std::uint32_t group_size);

// `table` with its clusters in the order `order` (new cluster i is the
// table's cluster order[i]); every per-cluster array moves with its
// cluster, the members keep their frame order.
ClusterTable reorder_clusters(const ClusterTable& table, std::span<const std::uint32_t> order);

}  // namespace mmvk::detail
