// k-means training for cluster tables: k-means++ seeding from a fixed seed,
// Lloyd iterations on a (documented) subsample, then every frame assigned to
// its nearest centroid. Distances here only steer the clustering, never a
// search result, so they may be computed in any order; everything is
// deterministic for given inputs (fixed chunking, sequential reductions).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <string>

#include "clusters/cluster_table_build.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {

namespace {

// Uniform integers and reals derived from the engine's raw output, which the
// standard specifies exactly (the std distributions differ between
// standard libraries).
std::uint64_t uniform_index(std::mt19937_64& rng, std::uint64_t n) {
  const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
  std::uint64_t x = rng();
  while (x >= limit) x = rng();
  return x % n;
}

double uniform_unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

float squared_distance(const float* a, const float* b, std::uint32_t dims) {
  // Four partial sums break the add dependency chain (training only).
  float s[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  std::uint32_t d = 0;
  for (; d + 4 <= dims; d += 4) {
    for (std::uint32_t l = 0; l < 4; ++l) {
      const float diff = a[d + l] - b[d + l];
      s[l] += diff * diff;
    }
  }
  for (; d < dims; ++d) {
    const float diff = a[d] - b[d];
    s[0] += diff * diff;
  }
  return (s[0] + s[1]) + (s[2] + s[3]);
}

// Runs body(begin, end, thread) over [0, count) on the pool, or inline.
template <class Body>
void run_parallel(ThreadPool* pool, std::size_t count, const Body& body) {
  if (pool == nullptr) {
    body(std::size_t{0}, count, 0u);
    return;
  }
  pool->parallel_for(count, [&](std::size_t begin, std::size_t end, unsigned thread) { body(begin, end, thread); });
}

// Nearest centroid of every point. Centroids are transposed [dims x k] so the
// inner loop runs over centroids and vectorizes without reassociation.
class Assigner {
 public:
  Assigner(std::uint32_t dims, std::uint32_t k, ThreadPool* pool) : dims_(dims), k_(k), pool_(pool) {
    const unsigned threads = pool == nullptr ? 1 : pool->thread_count();
    scratch_.assign(threads, std::vector<float>(k));
    transposed_.resize(std::size_t{dims} * k);
  }

  // points [count x dims]; writes assignment[count] and distance[count].
  void assign(const float* points, std::size_t count, const std::vector<float>& centroids,
              std::vector<std::uint32_t>& assignment, std::vector<float>& distance) {
    for (std::uint32_t j = 0; j < k_; ++j) {
      for (std::uint32_t d = 0; d < dims_; ++d) transposed_[std::size_t{d} * k_ + j] = centroids[std::size_t{j} * dims_ + d];
    }
    assignment.resize(count);
    distance.resize(count);
    run_parallel(pool_, count, [&](std::size_t begin, std::size_t end, unsigned thread) {
      float* dist = scratch_[thread].data();
      for (std::size_t i = begin; i < end; ++i) {
        const float* x = points + i * dims_;
        std::fill(dist, dist + k_, 0.0f);
        for (std::uint32_t d = 0; d < dims_; ++d) {
          const float xd = x[d];
          const float* column = transposed_.data() + std::size_t{d} * k_;
          for (std::uint32_t j = 0; j < k_; ++j) {
            const float diff = xd - column[j];
            dist[j] += diff * diff;
          }
        }
        std::uint32_t best = 0;
        for (std::uint32_t j = 1; j < k_; ++j) {
          if (dist[j] < dist[best]) best = j;
        }
        assignment[i] = best;
        distance[i] = dist[best];
      }
    });
  }

 private:
  std::uint32_t dims_;
  std::uint32_t k_;
  ThreadPool* pool_;
  std::vector<std::vector<float>> scratch_;
  std::vector<float> transposed_;
};

std::vector<float> kmeans_plus_plus(const std::vector<float>& points, std::size_t count, std::uint32_t dims,
                                    std::uint32_t k, std::mt19937_64& rng, ThreadPool* pool,
                                    const std::function<void(std::uint32_t)>& on_centroid) {
  std::vector<float> centroids(std::size_t{k} * dims);
  std::vector<float> min_distance(count, std::numeric_limits<float>::infinity());
  std::size_t chosen = uniform_index(rng, count);
  for (std::uint32_t c = 0; c < k; ++c) {
    std::copy_n(points.data() + chosen * dims, dims, centroids.data() + std::size_t{c} * dims);
    if (on_centroid) on_centroid(c + 1);
    if (c + 1 == k) break;
    const float* center = centroids.data() + std::size_t{c} * dims;
    run_parallel(pool, count, [&](std::size_t begin, std::size_t end, unsigned) {
      for (std::size_t i = begin; i < end; ++i) {
        min_distance[i] = std::min(min_distance[i], squared_distance(points.data() + i * dims, center, dims));
      }
    });
    // D^2 sampling; the sequential double sum keeps it deterministic.
    double total = 0.0;
    for (std::size_t i = 0; i < count; ++i) total += min_distance[i];
    if (!(total > 0.0)) {
      chosen = uniform_index(rng, count);  // every point sits on a centroid already
      continue;
    }
    const double target = uniform_unit(rng) * total;
    double running = 0.0;
    chosen = count - 1;
    for (std::size_t i = 0; i < count; ++i) {
      running += min_distance[i];
      if (running > target && min_distance[i] > 0.0f) {
        chosen = i;
        break;
      }
    }
  }
  return centroids;
}

}  // namespace

Result<ClusterTable> train_cluster_table(const Database& database, const KMeansParams& params) {
  return detail::train_cluster_table_impl(database, params, nullptr);
}

Result<ClusterTable> train_cluster_table(const Database& database, const KMeansParams& params, ThreadPool& pool) {
  return detail::train_cluster_table_impl(database, params, &pool);
}

Result<ClusterTable> train_cluster_table(const Database& database, const KMeansParams& params, ThreadPool& pool,
                                         const TrainingProgressFn& progress) {
  return detail::train_cluster_table_impl(database, params, &pool, progress);
}

namespace detail {

void run_lloyd(const float* points, std::size_t count, std::uint32_t dims, std::vector<float>& centroids,
               std::uint32_t iterations, ThreadPool* pool, const std::function<void(std::uint32_t)>& on_iteration) {
  const auto k = static_cast<std::uint32_t>(centroids.size() / dims);
  Assigner assigner(dims, k, pool);
  std::vector<std::uint32_t> assignment;
  std::vector<std::uint32_t> previous;
  std::vector<float> distance;
  std::vector<double> sums(std::size_t{k} * dims);
  std::vector<std::uint32_t> sizes(k);
  for (std::uint32_t iteration = 0; iteration < iterations; ++iteration) {
    if (iteration != 0 && on_iteration) on_iteration(iteration);
    assigner.assign(points, count, centroids, assignment, distance);
    if (assignment == previous) break;  // converged: the update would change nothing
    previous = assignment;
    std::fill(sums.begin(), sums.end(), 0.0);
    std::fill(sizes.begin(), sizes.end(), 0u);
    for (std::size_t i = 0; i < count; ++i) {
      ++sizes[assignment[i]];
      for (std::uint32_t d = 0; d < dims; ++d) sums[std::size_t{assignment[i]} * dims + d] += points[i * dims + d];
    }
    for (std::uint32_t c = 0; c < k; ++c) {
      if (sizes[c] == 0) {
        // Re-seed an empty cluster at the point farthest from its centroid
        // (first such point on ties); zeroing its distance makes the next
        // empty cluster take another point.
        const std::size_t far = static_cast<std::size_t>(std::max_element(distance.begin(), distance.end()) - distance.begin());
        std::copy_n(points + far * dims, dims, centroids.data() + std::size_t{c} * dims);
        distance[far] = 0.0f;
        previous.clear();  // force another iteration
        continue;
      }
      for (std::uint32_t d = 0; d < dims; ++d) {
        centroids[std::size_t{c} * dims + d] = static_cast<float>(sums[std::size_t{c} * dims + d] / sizes[c]);
      }
    }
  }
}

Result<ClusterTable> train_cluster_table_impl(const Database& database, const KMeansParams& params, ThreadPool* pool,
                                              const TrainingProgressFn& progress) {
  const std::uint32_t frames = database.frame_count();
  const std::uint32_t dims = database.dims();
  if (frames == 0) return make_error("train_cluster_table: the database is empty");
  std::uint32_t k = params.clusters;
  if (k == 0) k = std::clamp<std::uint32_t>(static_cast<std::uint32_t>(std::lround(std::sqrt(double(frames)))), 1, frames);
  if (k > frames) {
    return make_error("train_cluster_table: clusters = " + std::to_string(k) + " exceeds the database's " +
                      std::to_string(frames) + " frames");
  }

  std::mt19937_64 rng(params.seed);
  // The training subsample: a partial Fisher-Yates shuffle, sorted back into
  // frame order so the result does not depend on the draw order.
  std::vector<std::uint32_t> sample(frames);
  std::iota(sample.begin(), sample.end(), 0u);
  std::size_t count = frames;
  if (params.max_training_frames != 0 && params.max_training_frames < frames) {
    count = std::max<std::size_t>(params.max_training_frames, k);
    for (std::size_t i = 0; i < count; ++i) std::swap(sample[i], sample[i + uniform_index(rng, frames - i)]);
    sample.resize(count);
    std::sort(sample.begin(), sample.end());
  }
  std::vector<float> points(count * dims);
  for (std::size_t i = 0; i < count; ++i) {
    const auto row = database.row(sample[i]);
    std::copy(row.begin(), row.end(), points.begin() + i * dims);
  }

  // Progress weights in distance evaluations: seeding is one pass over the
  // sample per centroid, an iteration k passes, the final assignment k
  // passes over every frame.
  const double seeding_work = double(count) * k;
  const double iteration_work = double(count) * k;
  const double total_work = seeding_work + iteration_work * params.iterations + double(frames) * k;
  const auto report = [&](const char* stage, std::uint32_t step, std::uint32_t steps, double done) {
    if (progress) progress(TrainingProgress{stage, step, steps, std::min(1.0, done / total_work)});
  };
  report("seeding", 0, k, 0.0);
  std::vector<float> centroids = kmeans_plus_plus(points, count, dims, k, rng, pool, [&](std::uint32_t chosen) {
    report("seeding", chosen, k, double(count) * chosen);
  });
  report("lloyd", 0, params.iterations, seeding_work);
  run_lloyd(points.data(), count, dims, centroids, params.iterations, pool, [&](std::uint32_t done) {
    report("lloyd", done, params.iterations, seeding_work + iteration_work * done);
  });

  // Every frame goes to its nearest trained centroid.
  const double assigning_start = seeding_work + iteration_work * params.iterations;
  report("assigning", 0, 1, assigning_start);
  Assigner assigner(dims, k, pool);
  std::vector<std::uint32_t> frame_cluster;
  std::vector<float> distance;
  assigner.assign(database.features().data(), frames, centroids, frame_cluster, distance);
  ClusterTable table = build_cluster_table(database, std::move(centroids), frame_cluster);
  report("assigning", 1, 1, total_work);
  return table;
}

}  // namespace detail

}  // namespace mmvk
