#include "faiss_peers.hpp"

#include <faiss/IndexFlat.h>
#include <faiss/IndexIVFFlat.h>
#include <faiss/index_io.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <fstream>
#include <string>
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

  Status fill() {
    return guarded(name(), [&] { index_.add(database_.frame_count(), database_.features().data()); });
  }

  std::size_t index_bytes() const override { return index_.codes.size(); }
  bool exact() const override { return false; }

  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override {
    MMVK_TRY(check_plain_batch(database_, batch, k, out, name()));
    labels_.resize(batch.size * k);
    distances_.resize(batch.size * k);
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
  std::vector<faiss::Index::idx_t> labels_;
  std::vector<float> distances_;
};

class FaissIvf final : public PeerBackend {
 public:
  FaissIvf(const Database& database, std::shared_ptr<FaissIvfIndex> index, std::uint32_t nprobe)
      : PeerBackend(database, "faiss-ivf" + std::to_string(nprobe)), index_(std::move(index)), nprobe_(nprobe) {}

  bool exact() const override { return false; }
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
  return std::unique_ptr<PeerBackend>(std::make_unique<FaissIvf>(database, std::move(index), nprobe));
}

}  // namespace mmvk::peers
