// The search semantics every backend implements (docs/search.md explains
// them in prose). One batched call answers a whole crowd's queries.
//
// Cost of a candidate frame i for a query q:
//   total_i = sum over channels c in schema order of  w_c * s_ic,
//             s_ic = sum over dims d of c in order of (x_id - q_d)^2,
//             accumulated in float from 0.0f, without FP contraction;
//   cost_i  = multiplier_i * total_i + bias_i;
//   when i is the continuing frame, then
//   cost_i  = cost_i * continuing_multiplier + continuing_bias
//             (two float operations in that order, not fused).
// Results are the best k frames sorted by (cost, frame id): equal costs go to
// the lower frame id.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "mmvk/database/database.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

class AsyncSearch;

inline constexpr std::uint32_t kNoFrame = 0xFFFFFFFFu;
inline constexpr std::uint32_t kMaxK = 16;
// The most queries one search call (and a device backend's max_batch) may
// hold: 2^20, a million characters searched at once, far above any crowd
// tick, and small enough that queries x dims (<= 2^27 floats, 512 MiB at
// 128 dims) and the B x k results (128 MiB at k = 16) stay allocatable and
// no size product can overflow. A larger batch is an error up front
// (validate_search), not an allocation failure; split it (docs/search.md).
// Every backend takes any batch up to this size; a device backend pages it
// over its own buffers.
inline constexpr std::size_t kMaxBatch = std::size_t{1} << 20;

// Per-query options. The defaults give a plain nearest-neighbour query.
struct QueryParams {
  // The frame the character plays next if it does not jump, or kNoFrame.
  std::uint32_t continuing_frame = kNoFrame;
  // Added to the continuing frame's cost (negative favours staying).
  float continuing_bias = 0.0f;
  // Multiplies the continuing frame's cost before continuing_bias is added
  // (finite, >= 0; below 1 favours staying while the cost is positive, as
  // Motion Symphony's favour-current or UE PoseSearch's continuing-pose
  // cost bias in multiplicative form).
  float continuing_multiplier = 1.0f;
  // Frames within +-exclusion_window of the continuing frame in the same clip
  // (wrapping for looping clips) are not candidates; the continuing frame
  // itself stays one.
  std::uint32_t exclusion_window = 0;
  TagMask require_all = 0;   // candidate tags must include all of these
  TagMask exclude_any = 0;   // candidate tags must include none of these
  // Weight of each schema channel (finite, >= 0; 0 turns the channel off).
  std::array<float, kMaxChannels> channel_weights = filled_weights();

  static constexpr std::array<float, kMaxChannels> filled_weights() {
    std::array<float, kMaxChannels> w{};
    w.fill(1.0f);
    return w;
  }
};

// The instruction set of the CPU backends' tile kernels (FastSearch,
// ClusterSearch). Widest: the widest this CPU runs (AVX-512F, AVX2, else the
// x86-64 baseline SSE2 "generic" ones). Forcing a set the CPU lacks makes
// the backend's create() an error; tests force each set the CPU has.
enum class CpuKernels { Widest, Generic, Avx2, Avx512 };

struct Match {
  std::uint32_t frame = kNoFrame;  // kNoFrame: no valid candidate ("none")
  float cost = std::numeric_limits<float>::infinity();

  friend bool operator==(const Match&, const Match&) = default;
};

// A batch of B queries.
struct QueryBatch {
  std::span<const float> features;     // [B x dims], normalized (Database::normalize)
  std::span<const QueryParams> params;  // [B], or empty: default params for every query
  std::size_t size = 0;                 // B
};

// Counters a backend accumulates over its calls (benchmarks report them).
struct SearchStats {
  std::uint64_t queries = 0;
  std::uint64_t rows_evaluated = 0;  // full cost evaluations
  double rows_fraction(std::uint32_t frame_count) const {
    return queries == 0 ? 0.0 : double(rows_evaluated) / (double(queries) * frame_count);
  }
};

class SearchBackend {
 public:
  virtual ~SearchBackend() = default;
  virtual std::string_view name() const = 0;
  // Where it runs, for a host to show: "cpu, 8 threads" (cpu_device_text),
  // or the device's own text ("llvmpipe (...) (Vulkan device 0, CPU,
  // software Vulkan)"). Every host shows this text as it is, so one backend
  // reads the same in the CLI, the crowd and Python.
  virtual std::string device() const = 0;
  virtual const Database& database() const = 0;
  // Writes B*k matches, query b's best k at out[b*k .. b*k+k), sorted by
  // (cost, frame); slots beyond the number of candidates are Match{} (none).
  virtual Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) = 0;
  virtual SearchStats stats() const = 0;
  virtual void reset_stats() = 0;
  // This backend behind the deferred interface (async_search.hpp) for
  // batches of up to `capacity` queries (<= kMaxBatch): a DeferredSearch,
  // which searches at submit, unless the backend runs in the background
  // (VulkanSearch). The backend must outlive it.
  virtual std::unique_ptr<AsyncSearch> make_async(std::uint32_t capacity);
};

// A CPU backend's device() on `threads` threads: "cpu, 1 thread",
// "cpu, 8 threads".
std::string cpu_device_text(unsigned threads);

// The checks every backend runs before searching: k in [1, kMaxK], a batch
// of at most kMaxBatch queries (checked before any size product), sizes,
// finite query features, params (continuing frame in range, weights finite
// and >= 0), an empty database, and costs that could overflow float (a
// finite query so far from every row, or a weight so large, that its cost
// bound exceeds FLT_MAX / 2). Errors name the query index and field.
Status validate_search(const Database& database, const QueryBatch& batch, std::uint32_t k, std::span<const Match> out);
// The same checks but the result span's size: for a batch submitted now
// whose results are written later (a paged device search).
Status validate_queries(const Database& database, const QueryBatch& batch, std::uint32_t k);

// True when every query inside the database's range (|q_d| <= max|row_d| in
// each dim, as queries made from the data's own poses are) can be searched
// with `params` without its costs overflowing float: the bound
// validate_search checks per query, for a host to check its settings
// (weights, continuing bias and multiplier) once, before it searches.
bool params_fit_cost_bound(const Database& database, const QueryParams& params);

// Sets the weight of the channel named `channel` in `params` (finite, >= 0;
// 0 turns the channel off); the error names an unknown channel.
Status set_channel_weight(const FeatureSchema& schema, QueryParams& params, std::string_view channel, float weight);

// True when frame `frame` may be a result for `params` (flags, tags and the
// exclusion window); the same rule every backend applies.
bool is_candidate(const Database& database, std::uint32_t frame, const QueryParams& params);

// The cost of frame `frame` for a query, in the documented order.
float frame_cost(const Database& database, std::uint32_t frame, std::span<const float> query, const QueryParams& params);

// Orders matches by (cost, frame).
inline bool match_less(const Match& a, const Match& b) {
  return a.cost < b.cost || (a.cost == b.cost && a.frame < b.frame);
}

}  // namespace mmvk
