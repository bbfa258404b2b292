// The data layout of the cluster kernels (cluster_*.comp): set 0 is the
// search layout (search_layout.glsl: the database texels, the query
// buffers, the results), set 1 the cluster table and the per-slot cluster
// scratch, plus their own push constants. The C++ side of every struct and
// binding here is runtime/vulkan/src/cluster_layout.hpp, with static_asserts
// on its size and offsets; change both together.
#ifndef MMVK_CLUSTER_LAYOUT_GLSL
#define MMVK_CLUSTER_LAYOUT_GLSL

#define MMVK_SEARCH_LAYOUT_OWN_PUSH
#define MMVK_QUERY_TEXELS
#include "search_layout.glsl"

// A bound key that is never visited (ineligible or not probed cluster).
// Orderable keys of non-NaN floats are at most 0xFF800000 (+inf).
const uint kSkip = 0xFFFFFFFFu;
// Flags that make a frame a non-candidate (mmvk::kFrameDoNotUse |
// kFrameEdgeExcluded | kFrameBlockTransition) when it is not continued.
const uint kNeverCandidate = 7u;
// Work items (one invocation each) per cluster_scan workgroup
// (cluster_layout.hpp: kScanWorkgroup); the scan is built with that size.
const uint kItemsPerScanGroup = 64u;
// Clusters per cluster_bounds invocation, at most (cluster_layout.hpp:
// kClustersPerBoundsInvocation): the host dispatches
// ceil(clusters / (workgroup size x this)) workgroups per query.
const uint kClustersPerBoundsInvocation = 128u;
// Blocks scan round 0 evaluates per query (cluster_select): those of least
// bound among the blocks of the kSeedClusters nearest clusters. Bandai
// volume set, transition: 2 blocks of 2 clusters visited 4.38% of the
// rows, 4 blocks 4.14%, 8 blocks 4.14%; 4 blocks of 3 or 4 clusters 3.91%
// and 3.82%.
const uint kSeedBlocks = 4u;
// Nearest clusters (by centroid) whose blocks cluster_select ranks. 3 took
// as long as 2 while cluster_select read the bound keys as storage-buffer
// loads; since it reads them as texels, 3 and 4 save about 1.5 ms a batch
// of 1,024 (the round-1 scan and merge gain more than the select costs;
// bench/RESULTS.md, 2026-11-27, "Both Vulkan targets on lavapipe's code
// for an AVX2 host").
const uint kSeedClusters = 3u;
// Most workgroups of an indirect cluster dispatch (Vulkan's minimum of
// maxComputeWorkGroupCount[0], cluster_layout.hpp: kMaxIndirectGroups);
// past it, invocations take several items (a grid-stride loop), so a
// chunk is not capped by its worst-case item count.
const uint kMaxIndirectGroups = 65535u;
// scan_dispatch entry of round 0's tiled scan (round 1's is the next one).
const uint kTileDispatchEntry = 2u;

// cluster_layout.hpp: ClusterPush (32 bytes).
layout(push_constant) uniform ClusterPush {
  uint query_base;     // first query of this chunk in the query buffers
  uint query_count;    // queries in this chunk
  uint k;              // the search's k (<= K)
  uint round;          // 0: cluster_select's blocks, 1: every other block that can win
  uint cluster_count;
  uint block_count;    // member blocks over all clusters
  uint nprobe;         // 0: exact; else clusters probed per query (< cluster_count)
  uint tile;           // work items per scan tile (cluster_sort, cluster_scan)
} pc;

// cluster_layout.hpp: ClusterQueryState (48 bytes, std430).
struct ClusterQueryState {
  uint pad0;
  uint upper_key;         // orderable key of the k-th best after round 0, kSkip if fewer than k
  uint rows;              // rows evaluated (statistics)
  uint pad1;
  uvec2 continuing_pair;  // (key, frame) of the continuing frame, (kNone, kNone) when not a candidate
  uvec2 items0;           // (first work item, count) of the query's blocks in scan round 0
  uvec2 items1;           // the same for round 1 (first counts from item 0 of round 0)
  uvec2 pad2;
};

// The rows in cluster order (ClusterTable::members, cluster by cluster),
// so that a block's rows are contiguous: the scans read them in place of
// the frame-ordered database (random gathers of the same rows were
// latency-bound on lavapipe).
// [members] RGBA32UI: (frame, flags, tags low 32 bits, tags high 32 bits).
layout(set = 1, binding = 0) uniform usamplerBuffer member_meta;
// [blocks x 2] RGBA32UI: (cluster, first member, end member, AND of the
// members' flags), (min multiplier bits, min bias bits, 0, 0) of the
// block's members; a cluster's members (ascending frames) split into blocks
// of at most rows_per_block.
layout(set = 1, binding = 1) uniform usamplerBuffer block_info;
// [clusters x 3] RGBA32UI: (flags_intersection, offsets[c], offsets[c+1],
// first block), (tag_union lo, hi, tag_intersection lo, hi),
// (min_multiplier bits, min_bias bits, end block, 0).
layout(set = 1, binding = 2) uniform usamplerBuffer cluster_info;
// [clusters x 3 x DV] RGBA32F: box_min, box_max, centroid, padded like rows.
layout(set = 1, binding = 3) uniform samplerBuffer cluster_vectors;
// [blocks x 2 x DV] RGBA32F: each member block's box_min, box_max.
layout(set = 1, binding = 4) uniform samplerBuffer block_vectors;
// [members x DV] RGBA32F: the feature rows, padded like the database's.
layout(set = 1, binding = 5) uniform samplerBuffer member_rows;
// [members] RG32F: (cost multiplier, cost bias).
layout(set = 1, binding = 6) uniform samplerBuffer member_cost;
// [chunk x clusters]: (bound key, centroid distance key), kSkip when skipped.
// Written by cluster_bounds (and cluster_select in nprobe mode) through the
// storage binding; the per-query loops over the clusters read it through
// the texel view, a vectorized gather on lavapipe where a storage-buffer
// load is a scalar loop over the lanes (shared/LAVAPIPE.md).
layout(set = 1, binding = 7) uniform usamplerBuffer bound_key_texels;
layout(std430, set = 1, binding = 11) buffer BoundKeys { uvec2 bound_keys[]; };
// Texel views of the slot's query buffers (set 0's query_features,
// query_params as 32-bit words, query_weights): the per-query kernels and
// the scan tiles load their queries through them, a gather per value
// where a storage-buffer load is a scalar loop over the lanes (the loads of
// a scan tile's 8 queries were about a third of the round-1 scan with
// lavapipe's code for an AVX2 host).
layout(set = 1, binding = 8) uniform samplerBuffer query_feature_texels;
layout(set = 1, binding = 9) uniform usamplerBuffer query_param_texels;
layout(set = 1, binding = 10) uniform samplerBuffer query_weight_texels;
// Words of a QueryGpu (search_layout.hpp: kQueryGpuWords).
const uint kQueryGpuWords = 17u;
vec4 query_feature(uint query, uint v) { return texelFetch(query_feature_texels, int(query * DV + v)); }
float query_weight(uint query, uint c) { return texelFetch(query_weight_texels, int(query * CHANNELS + c)).x; }
uint query_param_word(uint query, uint word) {
  return texelFetch(query_param_texels, int(query * kQueryGpuWords + word)).x;
}
// The words the kernel does not use are not fetched (dead after inlining).
QueryGpu query_params_of(uint q) {
  return QueryGpu(query_param_word(q, 0u), query_param_word(q, 1u), query_param_word(q, 2u), query_param_word(q, 3u),
                  query_param_word(q, 4u), query_param_word(q, 5u), query_param_word(q, 6u), query_param_word(q, 7u),
                  query_param_word(q, 8u), query_param_word(q, 9u), uintBitsToFloat(query_param_word(q, 10u)),
                  uintBitsToFloat(query_param_word(q, 11u)), query_param_word(q, 12u), query_param_word(q, 13u),
                  query_param_word(q, 14u), query_param_word(q, 15u), query_param_word(q, 16u));
}
// [max_batch] per query state, indexed by the query's batch index.
layout(std430, set = 1, binding = 12) buffer States { ClusterQueryState states[]; };
// [work items x K] the best (key, frame) pairs of each work item (round 0's
// items, then round 1's; at most chunk x blocks).
layout(std430, set = 1, binding = 13) buffer BlockPairs { uvec2 block_pairs[]; };
// Per scan round r: [r] = (workgroups x, 1, 1, work items), the indirect
// dispatch of cluster_sort's per-item steps, counted while listing; [2 + r]
// = (workgroups x, 1, 1, tiles), cluster_scan's, written by cluster_sort's
// prefix step (cluster_layout.hpp: kScanDispatchReset); the host zeroes
// them before each chunk.
layout(std430, set = 1, binding = 14) buffer ScanDispatch { uvec4 scan_dispatch[4]; };
// [chunk x blocks] (local query, block): the work items, each query's
// items of a round consecutive.
layout(std430, set = 1, binding = 15) buffer WorkItems { uvec2 work_items[]; };
// [chunk x blocks] per query: the blocks it lists, before they get their
// place among the work items.
layout(std430, set = 1, binding = 16) buffer Listed { uint listed[]; };
// The work items of a round sorted by block (cluster_sort.comp), so that a
// scan invocation evaluates one block for a tile of the queries that visit
// it (a row loaded once per tile, not once per query). Words, with
// B = block_count:
//   [0, 2B)             per round, the items listing each block (zeroed by
//                       the host before each chunk)
//   [2B, 3B + 1)        the first sorted position of each block's items
//   [3B + 1, 4B + 2)    the first tile of each block's items
//   [4B + 2 + 2i]       item i's rank among its block's items
//   [4B + 2 + 2j + 1]   the item at sorted position j of the round
layout(std430, set = 1, binding = 17) buffer BlockSort { uint block_sort[]; };
uint sort_fill(uint round, uint b) { return round * pc.block_count + b; }
uint sort_item_start(uint b) { return 2u * pc.block_count + b; }
uint sort_tile_start(uint b) { return 3u * pc.block_count + 1u + b; }
uint sort_rank(uint item) { return 4u * pc.block_count + 2u + 2u * item; }
uint sort_sorted(uint position) { return 4u * pc.block_count + 3u + 2u * position; }

#endif
