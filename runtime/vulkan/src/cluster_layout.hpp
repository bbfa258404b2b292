// The C++ side of shaders/cluster_layout.glsl: the push constants, the
// per-query state and the set 1 bindings of the cluster kernels, declared
// once per side, next to each other, with their sizes and offsets checked
// here. Change both files together.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "descriptors.hpp"

namespace mmvk::vulkan::detail {

// GLSL: ClusterPush (push constants of every cluster kernel).
struct ClusterPush {
  std::uint32_t query_base;
  std::uint32_t query_count;
  std::uint32_t k;
  std::uint32_t round;
  std::uint32_t cluster_count;
  std::uint32_t block_count;
  std::uint32_t nprobe;
  std::uint32_t tile;  // work items per scan tile
};
static_assert(sizeof(ClusterPush) == 32);
static_assert(sizeof(ClusterPush) <= 128, "Vulkan guarantees only 128 bytes of push constants");
static_assert(offsetof(ClusterPush, round) == 12);
static_assert(offsetof(ClusterPush, nprobe) == 24);

// GLSL: ClusterQueryState (std430 array element; uvec2 aligned to 8).
struct ClusterQueryState {
  std::uint32_t pad0;
  std::uint32_t upper_key;           // orderable key of the k-th best after scan round 0
  std::uint32_t rows;                // rows evaluated, read back for SearchStats
  std::uint32_t pad1;
  std::uint32_t continuing_pair[2];  // (key, frame) of the continuing frame
  std::uint32_t items0[2];           // (first work item, count) of scan round 0
  std::uint32_t items1[2];           // the same for round 1
  std::uint32_t pad2[2];
};
static_assert(sizeof(ClusterQueryState) == 48);
static_assert(offsetof(ClusterQueryState, rows) == 8);
static_assert(offsetof(ClusterQueryState, continuing_pair) == 16);
static_assert(offsetof(ClusterQueryState, items1) == 32);

// Descriptor bindings of set 1 (cluster_layout.glsl); set 0 is the search
// layout (search_layout.hpp).
enum ClusterBinding : std::uint32_t {
  kBindingMemberMeta = 0,          // uniform texel, RGBA32UI
  kBindingBlockInfo = 1,           // uniform texel, RGBA32UI, 2 per block
  kBindingClusterInfo = 2,         // uniform texel, RGBA32UI
  kBindingClusterVectors = 3,      // uniform texel, RGBA32F
  kBindingBlockVectors = 4,        // uniform texel, RGBA32F
  kBindingMemberRows = 5,          // uniform texel, RGBA32F
  kBindingMemberCost = 6,          // uniform texel, RG32F
  kBindingBoundKeyTexels = 7,      // uniform texel, RG32UI: a view of the bound keys' buffer
  kBindingQueryFeatureTexels = 8,  // uniform texel, RGBA32F: a view of the slot's query features (set 0)
  kBindingQueryParamTexels = 9,    // uniform texel, R32UI: the slot's QueryGpu array as words
  kBindingQueryWeightTexels = 10,  // uniform texel, R32F: the slot's query weights
  kBindingBoundKeys = 11,          // storage
  kBindingStates = 12,             // storage
  kBindingBlockPairs = 13,         // storage
  kBindingScanDispatch = 14,       // storage + indirect
  kBindingWorkItems = 15,          // storage
  kBindingListed = 16,             // storage
  kBindingBlockSort = 17,          // storage
  kClusterBindingCount = 18,
};
inline constexpr SetShape kClusterSet{11, 7};
static_assert(kClusterSet.texel == kBindingBoundKeys && kClusterSet.bindings() == kClusterBindingCount);

// The workgroup size of cluster_scan (one invocation per work item) and
// cluster_sort, on every device (Vulkan guarantees 128); GLSL:
// kItemsPerScanGroup.
inline constexpr std::uint32_t kScanWorkgroup = 64;
inline constexpr std::uint32_t kItemsPerScanGroup = kScanWorkgroup;
// Clusters per cluster_bounds invocation, at most (GLSL: the same name):
// the query's loads (storage-buffer loads, scalar loops over the lanes on
// lavapipe) are shared by them. The pass runs in the search's workgroup (8
// lanes on CPU drivers), so up to 8 x 128 clusters take one workgroup per
// query. Bandai volume set (646 clusters), transition, B = 1024, the pass
// alone, lavapipe's AVX2 / AVX-512 code: 5 clusters an invocation took
// about 15 / 7 ms a batch, 10 about 11 / 7.8, 81 about 6.4 / 5.7
// (bench/RESULTS.md, 2026-11-27, "Both Vulkan targets on lavapipe's code
// for an AVX2 host").
inline constexpr std::uint32_t kClustersPerBoundsInvocation = 128;

// GLSL: ScanDispatch, (groups x, 1, 1, count) per scan round for the
// per-item sort steps, then per round for the tiled scan; reset by the
// host before each chunk.
inline constexpr std::array<std::uint32_t, 16> kScanDispatchReset = {0, 1, 1, 0, 0, 1, 1, 0,
                                                                     0, 1, 1, 0, 0, 1, 1, 0};
inline constexpr std::uint64_t kScanDispatchStride = 16;  // bytes per entry (a uvec4)
inline constexpr std::uint32_t kTileDispatchEntry = 2;    // entry of round 0's tiled scan
// GLSL: kMaxIndirectGroups, the most workgroups of an indirect cluster
// dispatch (Vulkan's minimum maxComputeWorkGroupCount[0]); the kernels
// loop past it.
inline constexpr std::uint32_t kMaxIndirectGroups = 65535;
static_assert(sizeof(kScanDispatchReset) == 4 * kScanDispatchStride);

// GLSL: BlockSort, words before the per-item pairs (4 x blocks + 2), and
// words per work item (rank, sorted item).
inline constexpr std::uint64_t block_sort_header_words(std::uint64_t blocks) { return 4 * blocks + 2; }
inline constexpr std::uint64_t kBlockSortWordsPerItem = 2;

}  // namespace mmvk::vulkan::detail
