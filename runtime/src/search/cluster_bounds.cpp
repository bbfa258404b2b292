#include <algorithm>
#include <cmath>
#include <limits>

#include "search/cluster_search_state.hpp"

namespace mmvk::cluster_walk {

bool cluster_eligible(const ClusterSearch::Layout& l, const QueryParams& params, std::uint32_t c) {
  const ClusterTable& t = l.table;
  return !l.never_candidate[c] && (t.tag_union[c] & params.require_all) == params.require_all &&
         (t.tag_intersection[c] & params.exclude_any) == 0;
}

namespace {

// Rules out (NaN: never <= any threshold) each cluster of bound[first,
// last) that query `params` cannot take a frame from, and turns a bound that
// overflowed to NaN into -inf (it proves nothing: visited first). Returns
// the number of eligible clusters of the range. It runs for every query
// over every cluster, so the common case (no tag rules) is a branch-free
// loop that vectorizes; queries with tag rules take cluster_eligible() per
// cluster.
std::uint32_t mark_ineligible(const ClusterSearch::Layout& l, const QueryParams& params, float* bound,
                              std::uint32_t first, std::uint32_t last) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  constexpr float kMinusInfinity = -std::numeric_limits<float>::infinity();
  // A tag both required and excluded rules out every frame.
  if ((params.require_all & params.exclude_any) != 0) {
    std::fill(bound + first, bound + last, kNaN);
    return 0;
  }
  const std::uint8_t* never = l.never_candidate.data();
  if (params.require_all == 0 && params.exclude_any == 0) {
    // No tag rules (most queries): the table's own eligibility.
    std::uint32_t eligible = 0;
    for (std::uint32_t c = first; c < last; ++c) {
      const float b = std::isnan(bound[c]) ? kMinusInfinity : bound[c];
      bound[c] = never[c] != 0 ? kNaN : b;
      eligible += never[c] == 0 ? 1u : 0u;
    }
    return eligible;
  }
  std::uint32_t eligible = 0;
  for (std::uint32_t c = first; c < last; ++c) {
    const bool ok = cluster_eligible(l, params, c);
    const float b = std::isnan(bound[c]) ? kMinusInfinity : bound[c];
    bound[c] = ok ? b : kNaN;
    eligible += ok ? 1u : 0u;
  }
  return eligible;
}

// The eligible cluster (bound not NaN) with the smallest centroid distance,
// ties to the lower cluster id; kNoCluster when none is eligible. Two
// branch-free passes (the minimum, then its first cluster) rather than one
// branchy one: they run for every query over every cluster. Distances are
// finite or +inf (queries are validated finite); an eligible cluster with a
// NaN distance is taken only when no eligible one has a number.
std::uint32_t nearest_centroid(const float* distance, const float* bound, std::uint32_t clusters) {
  float nearest = std::numeric_limits<float>::infinity();
  for (std::uint32_t c = 0; c < clusters; ++c) {
    const float d = std::isnan(bound[c]) ? std::numeric_limits<float>::infinity() : distance[c];
    nearest = d < nearest ? d : nearest;
  }
  std::uint32_t first_eligible = kNoCluster;
  for (std::uint32_t c = 0; c < clusters; ++c) {
    if (std::isnan(bound[c])) continue;
    if (first_eligible == kNoCluster) first_eligible = c;
    if (distance[c] == nearest) return c;
  }
  return first_eligible;
}

// Lower bounds of every cluster into bound[] (padded to whole
// packs): NaN for a cluster the query rules out (never <= any threshold),
// -inf for a bound that overflowed to NaN (proves nothing: visited first).
// Returns the eligible cluster with the nearest centroid when seeding
// (ties: the lower cluster id), else kNoCluster. In nprobe mode the clusters
// beyond the nprobe nearest centroids are ruled out (NaN) as well.
std::uint32_t all_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound) {
  const ClusterSearch::Layout& l = x.l;
  const ClusterTable& t = l.table;
  const std::size_t cluster_packs = packs_of(t.cluster_count);
  if (x.options.box_bound) {
    l.kernels.box_bounds(l.cluster_boxes.arrays(l.rows.channel_end), 0, cluster_packs, v.q, v.w, bound);
  } else {
    std::copy(t.min_bias.begin(), t.min_bias.end(), bound);
  }
  const std::uint32_t eligible = mark_ineligible(l, *v.params, bound, 0, t.cluster_count);
  const bool probing = x.options.nprobe != 0 && x.options.nprobe < eligible;
  if (!probing && (!x.options.seed_nearest || eligible < 2)) return kNoCluster;
  l.kernels.box_bounds(l.centroids.arrays(l.rows.channel_end), 0, cluster_packs, v.q, v.w, s.distance.data());
  if (probing) {
    // nprobe mode: only the nprobe eligible clusters with the nearest
    // centroids (ties: the lower cluster id) stay eligible; the result is
    // the exact best over them, as in the one-query walk.
    s.order.clear();
    for (std::uint32_t c = 0; c < t.cluster_count; ++c) {
      if (!std::isnan(bound[c])) s.order.push_back({s.distance[c], l.table_id[c], 0.0f});
    }
    std::nth_element(s.order.begin(), s.order.begin() + x.options.nprobe, s.order.end());
    for (auto it = s.order.begin() + x.options.nprobe; it != s.order.end(); ++it) {
      bound[l.internal_id[it->cluster]] = std::numeric_limits<float>::quiet_NaN();
    }
  }
  return nearest_centroid(s.distance.data(), bound, t.cluster_count);
}

// The clusters [first, last) of group g.
std::uint32_t group_first(std::uint32_t g) { return g * kGroupClusters; }
std::uint32_t group_last(const ClusterSearch::Layout& l, std::uint32_t g) {
  return std::min(l.table.cluster_count, (g + 1) * kGroupClusters);
}

// The cluster bounds of group g into bound[], ineligible ones ruled out.
// Returns the number of eligible clusters.
std::uint32_t group_cluster_bounds(const WalkContext& x, const QueryView& v, std::uint32_t g, float* bound) {
  const ClusterSearch::Layout& l = x.l;
  const std::uint32_t first = group_first(g);
  const std::uint32_t last = group_last(l, g);
  const std::size_t first_pack = first / kLanes;
  l.kernels.box_bounds(l.cluster_boxes.arrays(l.rows.channel_end), first_pack, packs_of(last) - first_pack, v.q, v.w,
                       bound + first);
  return mark_ineligible(l, *v.params, bound, first, last);
}

// The cluster bounds of group g (group_cluster_bounds) and, when one is
// eligible, its centroid distances into s.distance. Returns the number of
// eligible clusters.
std::uint32_t examine_group(const WalkContext& x, Scratch& s, const QueryView& v, std::uint32_t g, float* bound) {
  const std::uint32_t eligible = group_cluster_bounds(x, v, g, bound);
  if (eligible == 0) return 0;
  const std::uint32_t first = group_first(g);
  const std::size_t first_pack = first / kLanes;
  x.l.kernels.box_bounds(x.l.centroids.arrays(x.l.rows.channel_end), first_pack,
                         packs_of(group_last(x.l, g)) - first_pack, v.q, v.w, s.distance.data() + first);
  return eligible;
}

// The group not done with the smallest group_distance (the first of equal
// ones, a NaN only when no number is left), kNoCluster when all are done.
std::uint32_t nearest_open_group(const ClusterSearch::Layout& l, const float* group_distance,
                                 const std::uint8_t* done) {
  std::uint32_t next = kNoCluster;
  for (std::uint32_t g = 0; g < l.group_count; ++g) {
    if (!done[g] && (next == kNoCluster || group_distance[g] < group_distance[next])) next = g;
  }
  return next;
}

}  // namespace

// nprobe mode with the group level: the same probed set as all_bounds()
// (the nprobe eligible clusters with the nearest centroids, ties to the
// caller's lower id) without ranking every centroid. Groups are examined in
// order of the bound of their centroids' box, which is at most any member's
// distance, until that bound is above the nprobe-th nearest distance found
// (equal: examined, it may hold a tie with a lower id); their cluster bounds
// and centroid distances are computed, and a max-heap keeps the nprobe
// nearest; the examined groups are marked done, and within them every
// cluster but the probed ones is ruled out (NaN). Leaves the probed
// clusters in s.order, nearest first (the caller's ids in .cluster, the
// lower bounds in .lower), and returns the nearest (kNoCluster when none is
// eligible).
std::uint32_t probe_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound, std::uint8_t* done) {
  const ClusterSearch::Layout& l = x.l;
  const std::uint32_t nprobe = x.options.nprobe;
  const std::size_t group_packs = packs_of(l.group_count);
  float* group_distance = s.group_distance.data();
  l.kernels.box_bounds(l.group_centroids.arrays(l.rows.channel_end), 0, group_packs, v.q, v.w, group_distance);
  for (std::uint32_t g = 0; g < l.group_count; ++g) done[g] = l.group_has_candidate[g] ? 0 : 1;
  std::vector<ClusterBound>& heap = s.order;  // max-heap by (distance, caller's id): the farthest on top
  heap.clear();
  for (;;) {
    const std::uint32_t next = nearest_open_group(l, group_distance, done);
    if (next == kNoCluster || (heap.size() == nprobe && group_distance[next] > heap.front().bound)) break;
    done[next] = 1;
    if (examine_group(x, s, v, next, bound) == 0) continue;
    const std::uint32_t first = group_first(next);
    const std::uint32_t last = group_last(l, next);
    for (std::uint32_t c = first; c < last; ++c) {
      if (std::isnan(bound[c])) continue;
      const ClusterBound candidate{s.distance[c], l.table_id[c], bound[c]};
      if (heap.size() < nprobe) {
        heap.push_back(candidate);
        std::push_heap(heap.begin(), heap.end());
      } else if (candidate < heap.front()) {
        std::pop_heap(heap.begin(), heap.end());
        heap.back() = candidate;
        std::push_heap(heap.begin(), heap.end());
      }
    }
  }
  std::sort_heap(heap.begin(), heap.end());
  // Only the probed clusters keep their bounds (carried in .lower); the
  // groups left unexamined (done 0) are never read.
  for (std::uint32_t g = 0; g < l.group_count; ++g) {
    if (done[g] && l.group_has_candidate[g]) {
      std::fill(bound + group_first(g), bound + group_last(l, g), std::numeric_limits<float>::quiet_NaN());
    }
  }
  for (const ClusterBound& b : heap) bound[l.internal_id[b.cluster]] = b.lower;
  return heap.empty() ? kNoCluster : l.internal_id[heap.front().cluster];
}

// The group level applies (more than one group, box bounds on).
bool use_groups(const WalkContext& x) { return x.options.box_bound && x.l.group_count > 1; }

// nprobe takes probe_bounds() up to a group's worth of probes: beyond that
// it examines most groups, and ranking every centroid at once was cheaper
// (volume set, 646 clusters: nprobe 1 and 16 took 26% and 11% less CPU
// time, nprobe 64 10% more).
bool probe_by_group(const WalkContext& x) {
  return x.options.nprobe != 0 && x.options.nprobe <= kGroupClusters && use_groups(x);
}

// Exact mode's bounds before the seed is visited. With the group level (box
// bounds and seeding on, more than one group; state Partial): the group
// bounds into group_bound[], and the seed, the eligible cluster with the
// nearest centroid (as all_bounds(), up to ties), found by visiting the
// groups in order of the bound of their centroids' box until that bound is
// above the nearest centroid found; the cluster bounds of those groups are
// computed (done[g] = 1), the rest is left to complete_bounds(), once the
// seed has tightened the k-th best. nprobe through the groups:
// probe_bounds() (state Probed). Otherwise every bound, as all_bounds()
// (state All).
std::uint32_t exact_bounds(const WalkContext& x, Scratch& s, const QueryView& v, float* bound, float* group_bound,
                           std::uint8_t* done, BoundState& state) {
  const ClusterSearch::Layout& l = x.l;
  if (probe_by_group(x)) {
    state = BoundState::Probed;
    return probe_bounds(x, s, v, bound, done);
  }
  state = BoundState::All;
  if (x.options.nprobe != 0 || !x.options.seed_nearest || !use_groups(x)) return all_bounds(x, s, v, bound);
  state = BoundState::Partial;
  const std::size_t group_packs = packs_of(l.group_count);
  l.kernels.box_bounds(l.group_boxes.arrays(l.rows.channel_end), 0, group_packs, v.q, v.w, group_bound);
  float* group_distance = s.group_distance.data();
  l.kernels.box_bounds(l.group_centroids.arrays(l.rows.channel_end), 0, group_packs, v.q, v.w, group_distance);
  for (std::uint32_t g = 0; g < l.group_count; ++g) done[g] = l.group_has_candidate[g] ? 0 : 1;
  std::uint32_t seed = kNoCluster;
  float nearest = std::numeric_limits<float>::infinity();
  for (;;) {
    const std::uint32_t next = nearest_open_group(l, group_distance, done);
    // A distance (or its group's lower bound) may be +inf or NaN: such
    // groups are only examined while no seed is found.
    if (next == kNoCluster || (seed != kNoCluster && !(group_distance[next] < nearest))) break;
    done[next] = 1;
    if (examine_group(x, s, v, next, bound) == 0) continue;
    const std::uint32_t first = group_first(next);
    const std::uint32_t last = group_last(l, next);
    const std::uint32_t in_group = nearest_centroid(s.distance.data() + first, bound + first, last - first);
    if (seed == kNoCluster || s.distance[first + in_group] < nearest) {
      seed = first + in_group;
      nearest = s.distance[seed];
    }
  }
  return seed;
}

// Exact mode after the seed (state Partial): the bounds of the clusters of
// the groups not done whose group bound is at most the k-th best, marked
// done. A group left out has its bound above a finite k-th best, which only
// falls, so none of its clusters could be visited.
void complete_bounds(const WalkContext& x, const QueryView& v, const float* group_bound, std::uint8_t* done,
                     BoundState state, float* bound) {
  const ClusterSearch::Layout& l = x.l;
  if (state != BoundState::Partial) return;
  const float threshold = v.best.back().cost;
  for (std::uint32_t g = 0; g < l.group_count; ++g) {
    if (done[g] || group_bound[g] > threshold) continue;
    group_cluster_bounds(x, v, g, bound);
    done[g] = 1;
  }
}

// Appends the clusters other than `skip` whose bound is at most `threshold`,
// sorted by (bound, cluster): over every cluster (state All) or over the
// groups done that hold candidates. They are compacted into `staging` (one
// slot per cluster) without a branch first: this runs for every query over
// every cluster, and which clusters pass follows no pattern a predictor
// learns.
void collect_candidates(const ClusterSearch::Layout& l, const float* bound, BoundState state,
                        const std::uint8_t* done, std::uint32_t skip, float threshold,
                        std::vector<ClusterBound>& staging, std::vector<ClusterBound>& out) {
  ClusterBound* passing = staging.data();
  std::size_t count = 0;
  const auto scan = [&](std::uint32_t first, std::uint32_t last) {
    for (std::uint32_t c = first; c < last; ++c) {
      passing[count] = {bound[c], c, 0.0f};
      count += c != skip && bound[c] <= threshold ? 1u : 0u;
    }
  };
  if (state == BoundState::All) {
    scan(0, l.table.cluster_count);
  } else {
    for (std::uint32_t g = 0; g < l.group_count; ++g) {
      if (done[g] && l.group_has_candidate[g]) scan(group_first(g), group_last(l, g));
    }
  }
  std::sort(passing, passing + count);
  out.insert(out.end(), passing, passing + count);
}

}  // namespace mmvk::cluster_walk
