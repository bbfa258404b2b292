#include "faiss_peers.hpp"

#include <faiss/IndexFlat.h>
#include <faiss/IndexIVFFlat.h>
#include <faiss/index_io.h>
#include <faiss/utils/distances.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace mmvk::peers {

class FaissIvfIndex {
 public:
  std::unique_ptr<faiss::IndexIVFFlat> ivf;  // owns its quantizer (own_fields)
};

namespace {

// FAISS reports errors by throwing; the suite wants a Status.
template <class Fn>
Status guarded(std::string_view what, Fn&& fn) {
  try {
    fn();
  } catch (const std::exception& e) {
    return make_error(std::string(what) + ": " + e.what());
  }
  return Status{};
}

// FAISS's knobs that decide a search's speed on a machine: its OpenMP
// threads and the rows of the database per BLAS block (each block is one
// sgemm and one OpenMP reduction over the queries, so a small block
// multiplies the threads' wake-ups; FAISS's default is 1024). Both are
// process-wide, so each peer sets its own before every search (the suite
// runs one cell at a time). The wait policy and the BLAS library are
// per process (bench/peers/README.md).
struct FaissSettings {
  int threads = 1;
  int database_bs = 1024;

  void apply() const {
    omp_set_num_threads(threads);
    faiss::distance_compute_blas_database_bs = database_bs;
  }
};

// The fastest of `candidates` for `search` (a warm-up, then the better of
// two timed runs), and the sweep's record: "omp_threads=2 blas_database_bs=16384
// (sweep, us/query: 1/1024 692, ...)".
template <class Search>
std::pair<FaissSettings, std::string> sweep(const std::vector<FaissSettings>& candidates, std::size_t queries,
                                            Search&& search) {
  FaissSettings best = candidates.front();
  double best_us = INFINITY;
  std::string figures;
  for (const FaissSettings& s : candidates) {
    s.apply();
    search();
    double us = INFINITY;
    for (int run = 0; run < 2; ++run) {
      const auto start = std::chrono::steady_clock::now();
      search();
      us = std::min(us, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() /
                            double(queries));
    }
    char line[64];
    std::snprintf(line, sizeof(line), "%s%d/%d %.1f", figures.empty() ? "" : ", ", s.threads, s.database_bs, us);
    figures += line;
    if (us < best_us) {
      best_us = us;
      best = s;
    }
  }
  return {best, "omp_threads=" + std::to_string(best.threads) + " blas_database_bs=" + std::to_string(best.database_bs) +
                    " (sweep, threads/block us/query: " + figures + ")"};
}

// 1 and every core, and the BLAS blocks to try when the search uses BLAS.
std::vector<FaissSettings> candidate_settings(bool blas) {
  std::vector<int> threads = {1};
  if (omp_get_num_procs() > 1) threads.push_back(omp_get_num_procs());
  // FAISS's default block and a 16x larger one (131072 rows never won at
  // 417k frames, B = 256 or 1024, here).
  std::vector<int> blocks = {1024};
  if (blas) blocks = {1024, 16384};
  std::vector<FaissSettings> all;
  for (const int t : threads)
    for (const int b : blocks) all.push_back({t, b});
  return all;
}

// `count` queries for a sweep: rows spread over the database, each moved
// off its row (so none is an exact match), the same on every run.
std::vector<float> sweep_queries(const Database& database, std::size_t count) {
  const std::size_t dims = database.dims();
  const std::size_t frames = database.frame_count();
  std::vector<float> queries(count * dims);
  for (std::size_t q = 0; q < count; ++q) {
    const float* row = database.features().data() + (q * frames / count) * dims;
    for (std::size_t d = 0; d < dims; ++d) queries[q * dims + d] = row[d] + 0.05f * float((q + d) % 7) - 0.15f;
  }
  return queries;
}

// FAISS's labels and distances for a batch, converted to Matches.
void to_matches(const std::vector<faiss::Index::idx_t>& labels, const std::vector<float>& distances, std::span<Match> out) {
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = labels[i] < 0 ? Match{} : Match{static_cast<std::uint32_t>(labels[i]), distances[i]};
  }
}

class FaissFlat final : public PeerBackend {
 public:
  FaissFlat(const Database& database, bool one_at_a_time)
      : PeerBackend(database, one_at_a_time ? "faiss-flat-1q" : "faiss-flat"),
        one_at_a_time_(one_at_a_time),
        index_(static_cast<faiss::Index::idx_t>(database.dims())) {}

  // Adds the rows, then picks the settings: for the batch form, the
  // threads and BLAS block of the fastest search of 1024 queries (the
  // suite's headline batch: at 417k frames 256 queries preferred a 16384-row
  // block, 1024 queries FAISS's 1024, by 10-20%); one query at a time (no
  // BLAS below 20 queries), the threads of the fastest 32 single-query
  // calls.
  Status fill() {
    return guarded(name(), [&] {
      index_.add(database_.frame_count(), database_.features().data());
      const std::size_t count = one_at_a_time_ ? 32 : 1024;
      const std::vector<float> queries = sweep_queries(database_, count);
      std::vector<float> distances(count);
      std::vector<faiss::Index::idx_t> labels(count);
      const std::size_t dims = database_.dims();
      std::tie(settings_, record_) = sweep(candidate_settings(!one_at_a_time_), count, [&] {
        if (one_at_a_time_) {
          for (std::size_t q = 0; q < count; ++q) index_.search(1, &queries[q * dims], 1, &distances[q], &labels[q]);
        } else {
          index_.search(static_cast<faiss::Index::idx_t>(count), queries.data(), 1, distances.data(), labels.data());
        }
      });
    });
  }

  std::size_t index_bytes() const override { return index_.codes.size(); }
  bool exact() const override { return false; }
  std::string settings() const override { return record_; }
  std::string device() const override { return cpu_device_text(unsigned(settings_.threads)); }

  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override {
    MMVK_TRY(check_plain_batch(database_, batch, k, out, name()));
    labels_.resize(batch.size * k);
    distances_.resize(batch.size * k);
    settings_.apply();
    MMVK_TRY(guarded(name(), [&] {
      const float* x = batch.features.data();
      if (one_at_a_time_) {
        for (std::size_t q = 0; q < batch.size; ++q) {
          index_.search(1, x + q * database_.dims(), k, &distances_[q * k], &labels_[q * k]);
        }
      } else {
        index_.search(static_cast<faiss::Index::idx_t>(batch.size), x, k, distances_.data(), labels_.data());
      }
    }));
    to_matches(labels_, distances_, out.first(batch.size * k));
    stats_.queries += batch.size;
    stats_.rows_evaluated += std::uint64_t{batch.size} * database_.frame_count();
    return Status{};
  }

 private:
  bool one_at_a_time_;
  faiss::IndexFlatL2 index_;
  FaissSettings settings_;
  std::string record_;
  std::vector<faiss::Index::idx_t> labels_;
  std::vector<float> distances_;
};

class FaissIvf final : public PeerBackend {
 public:
  // Picks the threads of the fastest search of 256 queries at this nprobe.
  FaissIvf(const Database& database, std::shared_ptr<FaissIvfIndex> index, std::uint32_t nprobe)
      : PeerBackend(database, "faiss-ivf" + std::to_string(nprobe)), index_(std::move(index)), nprobe_(nprobe) {}

  Status choose_settings() {
    return guarded(name(), [&] {
      constexpr std::size_t kCount = 256;
      const std::vector<float> queries = sweep_queries(database_, kCount);
      std::vector<float> distances(kCount);
      std::vector<faiss::Index::idx_t> labels(kCount);
      index_->ivf->nprobe = nprobe_;
      std::tie(settings_, record_) = sweep(candidate_settings(false), kCount, [&] {
        index_->ivf->search(static_cast<faiss::Index::idx_t>(kCount), queries.data(), 1, distances.data(), labels.data());
      });
    });
  }

  bool exact() const override { return false; }
  std::string settings() const override { return record_; }
  std::string device() const override { return cpu_device_text(unsigned(settings_.threads)); }
  std::size_t index_bytes() const override {
    const faiss::IndexIVFFlat& ivf = *index_->ivf;
    // The stored rows and their ids, plus the centroids.
    return ivf.ntotal * (ivf.code_size + sizeof(faiss::Index::idx_t)) + ivf.nlist * ivf.d * sizeof(float);
  }

  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override {
    MMVK_TRY(check_plain_batch(database_, batch, k, out, name()));
    labels_.resize(batch.size * k);
    distances_.resize(batch.size * k);
    faiss::IndexIVFFlat& ivf = *index_->ivf;
    // The backends of every nprobe share the index: set it per call.
    ivf.nprobe = nprobe_;
    settings_.apply();
    faiss::indexIVF_stats.reset();
    MMVK_TRY(guarded(name(), [&] {
      ivf.search(static_cast<faiss::Index::idx_t>(batch.size), batch.features.data(), k, distances_.data(), labels_.data());
    }));
    to_matches(labels_, distances_, out.first(batch.size * k));
    stats_.queries += batch.size;
    // Rows whose distance FAISS computed in the probed lists.
    stats_.rows_evaluated += faiss::indexIVF_stats.ndis;
    return Status{};
  }

 private:
  std::shared_ptr<FaissIvfIndex> index_;
  std::uint32_t nprobe_;
  FaissSettings settings_;
  std::string record_;
  std::vector<faiss::Index::idx_t> labels_;
  std::vector<float> distances_;
};

std::filesystem::path seconds_file(const std::filesystem::path& cache) {
  return std::filesystem::path(cache.string() + ".seconds");
}

}  // namespace

Result<std::unique_ptr<PeerBackend>> make_faiss_flat(const Database& database, bool one_query_at_a_time) {
  MMVK_TRY(check_plain_database(database, "faiss-flat"));
  auto flat = std::make_unique<FaissFlat>(database, one_query_at_a_time);
  MMVK_TRY(flat->fill());
  return std::unique_ptr<PeerBackend>(std::move(flat));
}

Result<FaissIvfBuild> build_faiss_ivf(const Database& database, const std::filesystem::path& cache) {
  MMVK_TRY(check_plain_database(database, "faiss-ivf"));
  FaissIvfBuild build{.index = std::make_shared<FaissIvfIndex>()};
  const std::size_t dims = database.dims();
  if (!cache.empty() && std::filesystem::exists(cache)) {
    faiss::Index* loaded = nullptr;
    Status read = guarded("faiss-ivf: " + cache.string(), [&] { loaded = faiss::read_index(cache.c_str()); });
    auto* ivf = dynamic_cast<faiss::IndexIVFFlat*>(loaded);
    if (read && ivf && ivf->ntotal == faiss::Index::idx_t{database.frame_count()} && std::size_t(ivf->d) == dims) {
      build.index->ivf.reset(ivf);
      std::ifstream seconds(seconds_file(cache));
      seconds >> build.build_seconds;
      return build;
    }
    delete loaded;
  }
  const std::size_t nlist = static_cast<std::size_t>(std::lround(4.0 * std::sqrt(double(database.frame_count()))));
  const auto start = std::chrono::steady_clock::now();
  MMVK_TRY(guarded("faiss-ivf", [&] {
    auto quantizer = std::make_unique<faiss::IndexFlatL2>(static_cast<faiss::Index::idx_t>(dims));
    build.index->ivf = std::make_unique<faiss::IndexIVFFlat>(quantizer.get(), dims, nlist, faiss::METRIC_L2);
    build.index->ivf->own_fields = true;  // the IVF index deletes the quantizer
    quantizer.release();
    build.index->ivf->train(database.frame_count(), database.features().data());
    build.index->ivf->add(database.frame_count(), database.features().data());
  }));
  build.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!cache.empty()) {
    MMVK_TRY(guarded("faiss-ivf: " + cache.string(), [&] { faiss::write_index(build.index->ivf.get(), cache.c_str()); }));
    std::ofstream(seconds_file(cache)) << build.build_seconds << "\n";
  }
  return build;
}

Result<std::unique_ptr<PeerBackend>> make_faiss_ivf(const Database& database, std::shared_ptr<FaissIvfIndex> index,
                                                    std::uint32_t nprobe) {
  if (!index || !index->ivf || index->ivf->ntotal != faiss::Index::idx_t{database.frame_count()}) {
    return make_error("faiss-ivf: the index was not built from this database");
  }
  if (nprobe == 0) return make_error("faiss-ivf: nprobe must be >= 1");
  auto ivf = std::make_unique<FaissIvf>(database, std::move(index), nprobe);
  MMVK_TRY(ivf->choose_settings());
  return std::unique_ptr<PeerBackend>(std::move(ivf));
}

}  // namespace mmvk::peers
