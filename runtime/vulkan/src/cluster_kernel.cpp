#include "cluster_kernel.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <span>
#include <string>

#include "cluster_layout.hpp"
#include "commands.hpp"
#include "pipeline.hpp"
#include "search_layout.hpp"

namespace mmvk::vulkan::detail {

namespace {

// Rows per member block (one scan invocation per (query, block)), the unit
// of block-level culling: a block is a k-d cell of a cluster's members
// (order_blocks), so its box is much tighter than its cluster's
// (ClusterSearch's 16-row tiles are the same idea). The smallest
// of these whose loops fit (block_rows_for). Smaller blocks visit fewer
// rows, but on lavapipe the costs that grow with the block count outweigh
// that: timed by kernel on the Bandai volume set (417k frames, transition
// queries, k = 1, B = 1024), the round-0 merge's block listing grew from
// 17 to 56 ms a batch between 256- and 32-row blocks and round 1's scan
// stayed at about 40 ms while its rows halved (per-tile costs); after the
// listing was made cheaper, 64 rows took 73 ms, 128 rows 55 ms and 256
// rows 51 ms (bench/RESULTS.md, 2026-11-27, "the time split by kernel");
// with k-d blocks, 128 rows visited 4.3% of the rows against 5.5% but took
// 106 ms a batch against 97 (one lavapipe thread, "k-d blocks").
constexpr std::uint32_t kBlockRows[] = {256, 512, 1024, 2048, 4096};
// Loop limits of one invocation (llvmpipe stops loops at 65,535 iterations
// in total): the round-0 merge walks the clusters, lists blocks and moves
// them, the round-1 merge inserts K pairs per block visited (counted as K
// iterations in case the compiler keeps that loop): at most
// cluster_count + (2 + K) x blocks. The nprobe selection walks the clusters
// 35 times.
constexpr std::uint64_t kMaxLoopIterations = 60000;
constexpr std::uint32_t kMaxProbeClusters = 1700;

// Work items per cluster_scan tile (one block, up to this many queries in
// registers; pad slots repeat a query): K = 1 keeps two registers per
// query, K > 1 keeps K pairs, as the brute force's tiles. Round 0 scans
// few blocks per query, each visited by few queries (2.8 items a block on
// the Bandai volume set, transition, B = 1,024), so most of a tile of 8
// would be pad slots, evaluated all the same: its tiles hold kRound0Tile.
constexpr std::uint32_t kRound0Tile = 2;
std::uint32_t scan_tile(std::uint32_t k_class, std::uint32_t round) {
  if (round == 0) return kRound0Tile;
  return k_class == 1 ? 8 : 4;
}

std::uint64_t loop_iterations(std::uint64_t clusters, std::uint64_t blocks, std::uint32_t k_class) {
  return clusters + (2 + std::uint64_t{k_class}) * blocks;
}

// Rows per block for `table` and the largest K class, 0 when no size fits.
std::uint32_t block_rows_for(const ClusterTable& table, std::uint32_t k_class) {
  for (const std::uint32_t rows : kBlockRows) {
    std::uint64_t blocks = 0;
    for (std::uint32_t c = 0; c < table.cluster_count; ++c) {
      blocks += (std::uint64_t{table.offsets[c + 1] - table.offsets[c]} + rows - 1) / rows;
    }
    if (loop_iterations(table.cluster_count, blocks, k_class) <= kMaxLoopIterations) return rows;
  }
  return 0;
}

// Between any two steps of a chunk: shader writes, the dispatch-argument
// reset (a transfer) and indirect reads are all ordered.
void full_barrier(VkCommandBuffer commands) {
  constexpr VkPipelineStageFlags stages =
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
  memory_barrier(commands, stages, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, stages,
                 VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                     VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
}

// The table in the kernels' layouts (cluster_layout.glsl); creation only.
struct PackedTable {
  std::vector<std::array<std::uint32_t, 4>> block_info;    // [blocks x 2]
  std::vector<std::array<std::uint32_t, 4>> cluster_info;  // [clusters x 3]
  std::vector<float> vectors;                              // [clusters x 3 x dim_vec4s x 4]
  std::vector<float> block_vectors;                        // [blocks x 2 x dim_vec4s x 4]
  // The rows in member order (cluster_layout.glsl: member_meta, member_rows, member_cost).
  std::vector<std::array<std::uint32_t, 4>> member_meta;  // [members]
  std::vector<float> member_rows;                         // [members x dim_vec4s x 4]
  std::vector<std::array<float, 2>> member_cost;          // [members]
  std::uint32_t block_count = 0;
};

// Member block [first, end) of `members` (ClusterTable::members, reordered): its two block_info texels and its
// box (min, max over the members, padded like the rows), appended. The
// minimum multiplier and bias and the AND of the flags cover every member,
// as the cluster's do, so the block's box bound is one too.
void pack_block(std::span<const std::uint32_t> members, const Database& database, std::uint32_t cluster,
                std::uint32_t first, std::uint32_t end, std::uint32_t dv, PackedTable& packed) {
  const std::uint32_t dims = database.dims();
  std::vector<float> lo(std::size_t{dv} * 4, 0.0f);
  std::vector<float> hi(std::size_t{dv} * 4, 0.0f);
  float min_multiplier = 0.0f;
  float min_bias = 0.0f;
  std::uint32_t flags = ~0u;
  for (std::uint32_t m = first; m < end; ++m) {
    const std::uint32_t frame = members[m];
    const std::span<const float> row = database.row(frame);
    const float multiplier = database.frame_multiplier()[frame];
    const float bias = database.frame_bias()[frame];
    for (std::uint32_t d = 0; d < dims; ++d) {
      lo[d] = m == first ? row[d] : std::min(lo[d], row[d]);
      hi[d] = m == first ? row[d] : std::max(hi[d], row[d]);
    }
    min_multiplier = m == first ? multiplier : std::min(min_multiplier, multiplier);
    min_bias = m == first ? bias : std::min(min_bias, bias);
    flags &= database.frame_flags()[frame];
  }
  packed.block_info.push_back({cluster, first, end, flags});
  packed.block_info.push_back(
      {std::bit_cast<std::uint32_t>(min_multiplier), std::bit_cast<std::uint32_t>(min_bias), 0, 0});
  packed.block_vectors.insert(packed.block_vectors.end(), lo.begin(), lo.end());
  packed.block_vectors.insert(packed.block_vectors.end(), hi.begin(), hi.end());
  ++packed.block_count;
}

// Orders members [first, end) into blocks of block_rows (the last one
// shorter) with tight boxes: the range splits at a multiple of block_rows
// near its middle, along the dimension of largest spread (a k-d split),
// until it is one block; each block's members then ascend by frame, which
// the scans' tie rule needs (a cluster's blocks need no order among
// themselves: the merges order pairs strictly). The variance picks the
// dimension (the range visited 5.75% of the Bandai volume set's rows, the
// variance 5.45%, runs of 256 members in frame order 6.2%).
void order_blocks(std::vector<std::uint32_t>& members, std::size_t first, std::size_t end, const Database& database,
                  std::uint32_t block_rows) {
  const auto begin = members.begin();
  if (end - first <= block_rows) {
    std::sort(begin + static_cast<std::ptrdiff_t>(first), begin + static_cast<std::ptrdiff_t>(end));
    return;
  }
  std::uint32_t widest = 0;
  double widest_spread = -1.0;
  for (std::uint32_t d = 0; d < database.dims(); ++d) {
    double sum = 0.0;
    double squares = 0.0;
    for (std::size_t m = first; m < end; ++m) {
      const double x = database.row(members[m])[d];
      sum += x;
      squares += x * x;
    }
    const double spread = squares - sum * sum / static_cast<double>(end - first);
    if (spread > widest_spread) {
      widest_spread = spread;
      widest = d;
    }
  }
  const std::size_t blocks = (end - first + block_rows - 1) / block_rows;
  const std::size_t middle = first + (blocks / 2) * block_rows;
  std::nth_element(begin + static_cast<std::ptrdiff_t>(first), begin + static_cast<std::ptrdiff_t>(middle),
                   begin + static_cast<std::ptrdiff_t>(end), [&](std::uint32_t a, std::uint32_t b) {
                     const float x = database.row(a)[widest];
                     const float y = database.row(b)[widest];
                     return x < y || (x == y && a < b);
                   });
  order_blocks(members, first, middle, database, block_rows);
  order_blocks(members, middle, end, database, block_rows);
}

PackedTable pack_table(const ClusterTable& table, const Database& database, const KernelShape& shape,
                       std::uint32_t block_rows) {
  std::vector<std::uint32_t> members = table.members;
  for (std::uint32_t c = 0; c < table.cluster_count; ++c) {
    order_blocks(members, table.offsets[c], table.offsets[c + 1], database, block_rows);
  }
  const std::uint32_t clusters = table.cluster_count;
  const std::uint32_t dv = shape.dim_vec4s;
  const std::uint32_t dims = shape.dims;
  PackedTable packed;
  const std::size_t member_count = table.members.size();
  packed.member_meta.resize(member_count);
  packed.member_rows.assign(member_count * dv * 4, 0.0f);
  packed.member_cost.resize(member_count);
  for (std::size_t m = 0; m < member_count; ++m) {
    const std::uint32_t frame = members[m];
    const TagMask tags = database.frame_tags()[frame];
    packed.member_meta[m] = {frame, database.frame_flags()[frame], static_cast<std::uint32_t>(tags),
                             static_cast<std::uint32_t>(tags >> 32)};
    packed.member_cost[m] = {database.frame_multiplier()[frame], database.frame_bias()[frame]};
    const std::span<const float> row = database.row(frame);
    std::copy(row.begin(), row.end(), packed.member_rows.begin() + static_cast<std::ptrdiff_t>(m * dv * 4));
  }
  packed.cluster_info.resize(std::size_t{clusters} * 3);
  packed.vectors.assign(std::size_t{clusters} * 3 * dv * 4, 0.0f);
  for (std::uint32_t c = 0; c < clusters; ++c) {
    const std::uint32_t first = table.offsets[c];
    const std::uint32_t end = table.offsets[c + 1];
    const std::uint32_t first_block = packed.block_count;
    for (std::uint32_t m = first; m < end; m += block_rows) {
      pack_block(members, database, c, m, std::min(end, m + block_rows), dv, packed);
    }
    const TagMask tag_union = table.tag_union[c];
    const TagMask tag_intersection = table.tag_intersection[c];
    std::array<std::uint32_t, 4>* info = &packed.cluster_info[std::size_t{c} * 3];
    info[0] = {table.flags_intersection[c], first, end, first_block};
    info[1] = {static_cast<std::uint32_t>(tag_union), static_cast<std::uint32_t>(tag_union >> 32),
               static_cast<std::uint32_t>(tag_intersection), static_cast<std::uint32_t>(tag_intersection >> 32)};
    info[2] = {std::bit_cast<std::uint32_t>(table.min_multiplier[c]), std::bit_cast<std::uint32_t>(table.min_bias[c]),
               packed.block_count, 0};
    float* box_min = &packed.vectors[std::size_t{c} * 3 * dv * 4];
    float* box_max = box_min + std::size_t{dv} * 4;
    float* centroid = box_max + std::size_t{dv} * 4;
    for (std::uint32_t d = 0; d < dims; ++d) {
      const std::size_t at = std::size_t{c} * dims + d;
      box_min[d] = table.box_min[at];
      box_max[d] = table.box_max[at];
      centroid[d] = table.centroids[at];
    }
  }
  return packed;
}

}  // namespace

Result<ClusterKernel> ClusterKernel::create(const Context& context, VkCommandPool pool,
                                            VkDescriptorSetLayout search_layout, const KernelShape& shape,
                                            const Database& database, const ClusterTable& table,
                                            const ClusterKernelOptions& options) {
  const std::array<SetShape, 2> sets = {kSearchSet, kClusterSet};
  MMVK_TRY(check_binding_limits(context, sets, "cluster kernels"));
  ClusterKernel kernel;
  // The per-query kernels (bounds, select, merge) use the search's
  // workgroup (8 on CPU drivers: one workgroup runs on one CPU thread, and a
  // chunk may hold only tens of queries); the grids (sort, scan) use
  // kScanWorkgroup.
  kernel.shape_ = shape;
  kernel.max_batch_ = options.max_batch;
  kernel.cluster_count_ = table.cluster_count;
  kernel.nprobe_ = options.nprobe < table.cluster_count ? options.nprobe : 0;
  if (kernel.nprobe_ != 0 && table.cluster_count > kMaxProbeClusters) {
    return make_error("Vulkan: nprobe search supports at most " + std::to_string(kMaxProbeClusters) +
                      " clusters, the table has " + std::to_string(table.cluster_count));
  }
  MMVK_TRY(kernel.upload_table(context, pool, database, table, k_class(options.max_k), options.force_staging));
  MMVK_TRY(kernel.create_layouts(context, search_layout, options.slots));
  MMVK_ASSIGN_OR_RETURN(const std::uint64_t chunk, kernel.size_scratch(context, options));
  MMVK_TRY(kernel.create_slots(context, options, chunk));
  MMVK_TRY(kernel.create_pipelines(context, options.max_k));
  return kernel;
}

Status ClusterKernel::upload_table(const Context& context, VkCommandPool pool, const Database& database,
                                   const ClusterTable& table, std::uint32_t largest_k_class, bool force_staging) {
  block_rows_ = block_rows_for(table, largest_k_class);
  if (block_rows_ == 0) {
    return make_error("Vulkan: the cluster table (" + std::to_string(table.cluster_count) +
                      " clusters) needs more member blocks than the cluster kernels' loops allow (clusters + (2 + " +
                      std::to_string(largest_k_class) + ") x blocks <= " + std::to_string(kMaxLoopIterations) +
                      "); use fewer clusters or a smaller max_k");
  }
  const PackedTable packed = pack_table(table, database, shape_, block_rows_);
  block_count_ = packed.block_count;
  const struct {
    TexelBuffer ClusterKernel::*member;
    VkFormat format;
    std::uint32_t texel_bytes;
    std::span<const std::byte> data;
    const char* what;
  } uploads[] = {
      {&ClusterKernel::member_meta_, VK_FORMAT_R32G32B32A32_UINT, 16, bytes_of(packed.member_meta),
       "the cluster members"},
      {&ClusterKernel::member_rows_, VK_FORMAT_R32G32B32A32_SFLOAT, 16, bytes_of(packed.member_rows),
       "the rows in cluster order"},
      {&ClusterKernel::member_cost_, VK_FORMAT_R32G32_SFLOAT, 8, bytes_of(packed.member_cost),
       "the cost terms in cluster order"},
      {&ClusterKernel::block_info_, VK_FORMAT_R32G32B32A32_UINT, 16, bytes_of(packed.block_info),
       "the member blocks"},
      {&ClusterKernel::cluster_info_, VK_FORMAT_R32G32B32A32_UINT, 16, bytes_of(packed.cluster_info),
       "the cluster info"},
      {&ClusterKernel::cluster_vectors_, VK_FORMAT_R32G32B32A32_SFLOAT, 16, bytes_of(packed.vectors),
       "the cluster boxes and centroids"},
      {&ClusterKernel::block_vectors_, VK_FORMAT_R32G32B32A32_SFLOAT, 16, bytes_of(packed.block_vectors),
       "the member block boxes"},
  };
  for (const auto& u : uploads) {
    MMVK_ASSIGN_OR_RETURN(this->*(u.member),
                          make_texel_buffer(context, pool, u.format, u.texel_bytes, u.data, u.what, force_staging));
  }
  return {};
}

// Set 1 layout, the pipeline layout (set 0 = the search layout) and a pool
// for one set 1 per slot.
Status ClusterKernel::create_layouts(const Context& context, VkDescriptorSetLayout search_layout,
                                     std::uint32_t slots) {
  MMVK_ASSIGN_OR_RETURN(set_layout_, create_set_layout(context, kClusterSet));
  const std::array<VkDescriptorSetLayout, 2> set_layouts = {search_layout, set_layout_.get()};
  MMVK_ASSIGN_OR_RETURN(pipeline_layout_,
                        create_pipeline_layout(context, set_layouts, sizeof(ClusterPush), "cluster kernels"));
  MMVK_ASSIGN_OR_RETURN(descriptor_pool_, create_descriptor_pool(context, kClusterSet, slots));
  return {};
}

// Queries per chunk: at least one, at most max_batch, within the scratch
// budget and maxStorageBufferRange.
Result<std::uint64_t> ClusterKernel::size_scratch(const Context& context, const ClusterKernelOptions& options) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  const std::uint64_t range = limits.maxStorageBufferRange;
  const std::uint64_t clusters = cluster_count_;
  const std::uint64_t pairs_per_query = std::uint64_t{block_count_} * k_class(options.max_k);
  // Bound keys, block pairs, work items (8 bytes each) and listed blocks
  // (4 bytes): a query lists each block at most once over both rounds.
  // The block sort: a rank and a sorted position per work item, and a
  // header of 4 words per block.
  const std::uint64_t sort_header = block_sort_header_words(block_count_) * 4;
  const std::uint64_t sort_per_query = std::uint64_t{block_count_} * kBlockSortWordsPerItem * 4;
  const std::uint64_t per_query_bytes =
      (pairs_per_query + clusters) * 8 + std::uint64_t{block_count_} * 12 + sort_per_query;
  if (sort_header + sort_per_query > range) {
    return make_error("Vulkan: one query's cluster block sort exceeds maxStorageBufferRange");
  }
  std::uint64_t chunk = std::clamp<std::uint64_t>(options.scratch_bytes / per_query_bytes, 1, options.max_batch);
  // The indirect dispatches are capped at kMaxIndirectGroups workgroups
  // (the kernels loop past it), so the item count does not cap the chunk
  // (it did: 314 queries at 417k frames, too few to share blocks).
  chunk = std::min({chunk, range / (pairs_per_query * 8), range / (clusters * 8),
                    std::uint64_t{limits.maxTexelBufferElements} / clusters,
                    range / (std::uint64_t{block_count_} * 8), (range - sort_header) / sort_per_query,
                    std::uint64_t{limits.maxComputeWorkGroupCount[1]}});
  if (chunk == 0) return make_error("Vulkan: one query's cluster scratch exceeds maxStorageBufferRange");
  bound_capacity_ = chunk * clusters;
  pair_capacity_ = chunk * pairs_per_query;
  item_chunk_ = chunk;
  return chunk;
}

// Per slot: the scratch buffers and their set 1, written once.
Status ClusterKernel::create_slots(const Context& context, const ClusterKernelOptions& options, std::uint64_t chunk) {
  if (options.slot_queries.size() != options.slots) {
    return make_error("Vulkan: the cluster kernels need the query buffers of each of the " +
                      std::to_string(options.slots) + " slots");
  }
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const struct {
    Buffer SlotScratch::*member;
    std::uint64_t bytes;
    VkBufferUsageFlags usage;
    MemoryUse use;
    const char* what;
  } buffers[] = {
      {&SlotScratch::bound_keys, bound_capacity_ * 8, storage | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT,
       MemoryUse::DeviceLocal, "the cluster bound keys"},
      {&SlotScratch::states, std::uint64_t{options.max_batch} * sizeof(ClusterQueryState), storage,
       MemoryUse::HostMapped, "the cluster query states"},
      {&SlotScratch::block_pairs, pair_capacity_ * 8, storage, MemoryUse::DeviceLocal, "the cluster block pairs"},
      {&SlotScratch::scan_dispatch, sizeof(kScanDispatchReset),
       storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::DeviceLocal,
       "the cluster scan dispatch arguments"},
      {&SlotScratch::work_items, chunk * block_count_ * 8, storage, MemoryUse::DeviceLocal, "the cluster work items"},
      {&SlotScratch::listed, chunk * block_count_ * 4, storage, MemoryUse::DeviceLocal, "the cluster listed blocks"},
      {&SlotScratch::block_sort,
       (block_sort_header_words(block_count_) + chunk * block_count_ * kBlockSortWordsPerItem) * 4,
       storage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::DeviceLocal, "the cluster block sort"},
  };
  static_assert(std::size(buffers) == kClusterSet.storage);
  slots_.resize(options.slots);
  for (SlotScratch& slot : slots_) {
    std::array<VkBuffer, kClusterSet.storage> handles{};
    for (std::size_t b = 0; b < std::size(buffers); ++b) {
      MMVK_ASSIGN_OR_RETURN(slot.*(buffers[b].member), create_buffer(context, buffers[b].bytes, buffers[b].usage,
                                                                     buffers[b].use, buffers[b].what));
      handles[b] = (slot.*(buffers[b].member)).buffer.get();
    }
    MMVK_ASSIGN_OR_RETURN(slot.bound_key_view, create_texel_view(context, slot.bound_keys, VK_FORMAT_R32G32_UINT, 8,
                                                                 slot.bound_keys.size, "the cluster bound keys"));
    const SlotQueryBuffers& queries = options.slot_queries[static_cast<std::size_t>(&slot - slots_.data())];
    MMVK_ASSIGN_OR_RETURN(slot.query_feature_view,
                          create_texel_view(context, *queries.features, VK_FORMAT_R32G32B32A32_SFLOAT, 16,
                                            queries.features->size, "the query features"));
    MMVK_ASSIGN_OR_RETURN(slot.query_param_view, create_texel_view(context, *queries.params, VK_FORMAT_R32_UINT, 4,
                                                                   queries.params->size, "the query parameters"));
    MMVK_ASSIGN_OR_RETURN(slot.query_weight_view, create_texel_view(context, *queries.weights, VK_FORMAT_R32_SFLOAT, 4,
                                                                    queries.weights->size, "the query weights"));
    const std::array<VkBufferView, kClusterSet.texel> views = {
        member_meta_.view.get(),      block_info_.view.get(),       cluster_info_.view.get(),
        cluster_vectors_.view.get(),  block_vectors_.view.get(),    member_rows_.view.get(),
        member_cost_.view.get(),      slot.bound_key_view.get(),    slot.query_feature_view.get(),
        slot.query_param_view.get(),  slot.query_weight_view.get()};
    MMVK_ASSIGN_OR_RETURN(slot.set, allocate_set(context, descriptor_pool_.get(), set_layout_.get(), views, handles));
  }
  return {};
}

// Bounds and select once, scan and merge per K class.
Status ClusterKernel::create_pipelines(const Context& context, std::uint32_t max_k) {
  const VkPipelineLayout layout = pipeline_layout_.get();
  KernelShape grid_shape = shape_;
  grid_shape.workgroup_size = kScanWorkgroup;
  MMVK_ASSIGN_OR_RETURN(bounds_, create_compute_pipeline(context, layout, "cluster_bounds", shape_spec(shape_, 1)));
  MMVK_ASSIGN_OR_RETURN(select_, create_compute_pipeline(context, layout, "cluster_select", shape_spec(shape_, 1)));
  for (std::uint32_t step = 0; step < std::size(sort_); ++step) {
    std::vector<SpecValue> spec = shape_spec(grid_shape, 1);
    spec.push_back({kSpecSortStep, step});
    MMVK_ASSIGN_OR_RETURN(sort_[step], create_compute_pipeline(context, layout, "cluster_sort", spec));
  }
  for (const std::uint32_t k : {1u, 4u, 16u}) {
    if (k > k_class(max_k)) break;
    Variant variant{k, {}, {}};
    for (std::uint32_t round = 0; round < 2; ++round) {
      std::vector<SpecValue> scan_spec = shape_spec(grid_shape, k);
      scan_spec.push_back({kSpecTile, scan_tile(k, round)});
      MMVK_ASSIGN_OR_RETURN(variant.scan[round], create_compute_pipeline(context, layout, "cluster_scan", scan_spec));
    }
    MMVK_ASSIGN_OR_RETURN(variant.merge,
                          create_compute_pipeline(context, layout, "cluster_merge", shape_spec(shape_, k)));
    variants_.push_back(std::move(variant));
  }
  return {};
}

std::vector<std::uint32_t> ClusterKernel::k_classes() const {
  std::vector<std::uint32_t> classes;
  for (const Variant& v : variants_) classes.push_back(v.k_class);
  return classes;
}

std::uint64_t ClusterKernel::device_bytes() const {
  std::uint64_t bytes = 0;
  for (const TexelBuffer* table : {&member_meta_, &member_rows_, &member_cost_, &block_info_, &cluster_info_,
                                   &cluster_vectors_, &block_vectors_}) {
    bytes += table->buffer.size;
  }
  for (const SlotScratch& slot : slots_) {
    for (const Buffer* buffer : {&slot.bound_keys, &slot.states, &slot.block_pairs, &slot.scan_dispatch,
                                 &slot.work_items, &slot.listed, &slot.block_sort}) {
      bytes += buffer->size;
    }
  }
  return bytes;
}

std::vector<std::string_view> ClusterKernel::kernel_names() const {
  std::vector<std::string_view> names = {"cluster_bounds", "cluster_select", "cluster_sort", "cluster_sort",
                                         "cluster_sort"};
  for (std::size_t v = 0; v < variants_.size(); ++v) {
    names.push_back("cluster_scan");
    names.push_back("cluster_scan");
    names.push_back("cluster_merge");
  }
  return names;
}

std::uint32_t ClusterKernel::chunk_for(std::uint32_t kc) const {
  // The work items and listed blocks hold item_chunk_ queries whatever k.
  const std::uint64_t chunk =
      std::min({bound_capacity_ / cluster_count_, pair_capacity_ / (std::uint64_t{block_count_} * kc),
                item_chunk_});
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(chunk, max_batch_));
}

Status ClusterKernel::record(const Context& context, VkCommandBuffer commands, std::uint32_t slot,
                             VkDescriptorSet search_set, std::uint32_t batch, std::uint32_t k) const {
  const std::uint32_t kc = k_class(k);
  const Variant* variant = nullptr;
  for (const Variant& v : variants_) {
    if (v.k_class == kc) variant = &v;
  }
  if (variant == nullptr || slot >= slots_.size()) {
    return make_error("Vulkan: no cluster kernel variant for k = " + std::to_string(k));
  }
  const std::uint32_t wg = shape_.workgroup_size;
  const std::uint32_t chunk = chunk_for(kc);
  const SlotScratch& scratch = slots_[slot];
  const std::array<VkDescriptorSet, 2> sets = {search_set, scratch.set};
  const VkPipelineLayout layout = pipeline_layout_.get();
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 2, sets.data(), 0, nullptr);
  const std::uint32_t items_per_group = kItemsPerScanGroup;
  const std::uint32_t bounds_clusters = wg * kClustersPerBoundsInvocation;
  const std::uint32_t bounds_groups = (cluster_count_ + bounds_clusters - 1) / bounds_clusters;
  for (std::uint32_t base = 0; base < batch; base += chunk) {
    const std::uint32_t count = std::min(chunk, batch - base);
    ClusterPush push{base, count, k, 0, cluster_count_, block_count_, nprobe_, 0};
    const std::uint32_t query_groups = (count + wg - 1) / wg;
    // The previous chunk's last merge read the scratch this chunk rewrites.
    if (base != 0) full_barrier(commands);
    vkCmdUpdateBuffer(commands, scratch.scan_dispatch.buffer.get(), 0, sizeof(kScanDispatchReset),
                      kScanDispatchReset.data());
    // Both rounds' per-block item counters.
    vkCmdFillBuffer(commands, scratch.block_sort.buffer.get(), 0, std::uint64_t{block_count_} * 2 * 4, 0);
    MMVK_TRY(dispatch(context, commands, bounds_.get(), layout, push, bounds_groups, count, "cluster_bounds"));
    full_barrier(commands);
    MMVK_TRY(dispatch(context, commands, select_.get(), layout, push, query_groups, 1, "cluster_select"));
    // A round lists each (query, block) at most once, so its work items
    // need at most this many workgroups, capped (the kernels loop past it).
    const std::uint64_t max_scan_groups = std::min<std::uint64_t>(
        (std::uint64_t{count} * block_count_ + items_per_group - 1) / items_per_group, kMaxIndirectGroups);
    for (std::uint32_t round = 0; round < 2; ++round) {
      push.round = round;
      push.tile = scan_tile(kc, round);
      // The work items (and so the group counts) were listed on the GPU:
      // sorted by block (rank, prefix sums, scatter), then scanned by tile.
      for (std::uint32_t step = 0; step < std::size(sort_); ++step) {
        full_barrier(commands);
        if (step == 1) {
          MMVK_TRY(dispatch(context, commands, sort_[step].get(), layout, push, 1, 1, "cluster_sort"));
        } else {
          MMVK_TRY(dispatch_indirect(context, commands, sort_[step].get(), layout, push, scratch.scan_dispatch,
                                     round * kScanDispatchStride, max_scan_groups, "cluster_sort"));
        }
      }
      full_barrier(commands);
      MMVK_TRY(dispatch_indirect(context, commands, variant->scan[round].get(), layout, push, scratch.scan_dispatch,
                                 (kTileDispatchEntry + round) * kScanDispatchStride, max_scan_groups, "cluster_scan"));
      full_barrier(commands);
      MMVK_TRY(dispatch(context, commands, variant->merge.get(), layout, push, query_groups, 1, "cluster_merge"));
    }
  }
  return {};
}

std::uint64_t ClusterKernel::rows_evaluated(std::uint32_t slot, std::uint32_t batch) const {
  const auto* states = static_cast<const ClusterQueryState*>(slots_[slot].states.mapped);
  std::uint64_t rows = 0;
  for (std::uint32_t q = 0; q < batch; ++q) rows += states[q].rows;
  return rows;
}

}  // namespace mmvk::vulkan::detail
