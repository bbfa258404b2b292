#include "pca_kdtree.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

namespace mmvk::peers {

namespace {

// nanoflann's view of the projected rows, [N x kPcaComponents].
struct ProjectedRows {
  std::vector<float> values;
  std::size_t dims = 0;
  std::size_t kdtree_get_point_count() const { return dims == 0 ? 0 : values.size() / dims; }
  float kdtree_get_pt(std::size_t row, std::size_t dim) const { return values[row * dims + dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;  // let nanoflann compute it
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, ProjectedRows>, ProjectedRows, -1,
                                                 std::uint32_t>;

}  // namespace

class PcaKdTreeIndex {
 public:
  std::size_t dims = 0;        // of the database
  std::size_t components = 0;  // of the projection
  std::vector<float> mean;     // [dims]
  std::vector<float> axes;     // [components x dims]
  ProjectedRows rows;
  std::unique_ptr<Tree> tree;

  void project(const float* x, float* out) const {
    for (std::size_t c = 0; c < components; ++c) {
      float sum = 0.0f;
      for (std::size_t d = 0; d < dims; ++d) sum += (x[d] - mean[d]) * axes[c * dims + d];
      out[c] = sum;
    }
  }
};

void symmetric_eigen(std::vector<double> a, std::size_t n, std::vector<double>& values, std::vector<double>& vectors) {
  std::vector<double> v(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) v[i * n + i] = 1.0;
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0.0, scale = 0.0;
    for (std::size_t p = 0; p < n; ++p) {
      scale += a[p * n + p] * a[p * n + p];
      for (std::size_t q = p + 1; q < n; ++q) off += a[p * n + q] * a[p * n + q];
    }
    if (off <= 1e-24 * scale) break;
    for (std::size_t p = 0; p < n; ++p) {
      for (std::size_t q = p + 1; q < n; ++q) {
        const double apq = a[p * n + q];
        if (apq == 0.0) continue;
        // The rotation that zeroes a[p][q] (cot 2phi = theta, t = tan phi,
        // the smaller root for stability).
        const double theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (std::size_t k = 0; k < n; ++k) {  // A J
          const double akp = a[k * n + p], akq = a[k * n + q];
          a[k * n + p] = c * akp - s * akq;
          a[k * n + q] = s * akp + c * akq;
        }
        for (std::size_t k = 0; k < n; ++k) {  // J^T (A J)
          const double apk = a[p * n + k], aqk = a[q * n + k];
          a[p * n + k] = c * apk - s * aqk;
          a[q * n + k] = s * apk + c * aqk;
        }
        for (std::size_t k = 0; k < n; ++k) {  // V J: eigenvectors in columns
          const double vkp = v[k * n + p], vkq = v[k * n + q];
          v[k * n + p] = c * vkp - s * vkq;
          v[k * n + q] = s * vkp + c * vkq;
        }
      }
    }
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return a[x * n + x] > a[y * n + y]; });
  values.resize(n);
  vectors.resize(n * n);
  for (std::size_t i = 0; i < n; ++i) {
    values[i] = a[order[i] * n + order[i]];
    for (std::size_t k = 0; k < n; ++k) vectors[i * n + k] = v[k * n + order[i]];
  }
}

Result<std::shared_ptr<PcaKdTreeIndex>> build_pca_kdtree(const Database& database) {
  MMVK_TRY(check_plain_database(database, "pca-kdtree"));
  auto index = std::make_shared<PcaKdTreeIndex>();
  const std::size_t n = database.dims(), frames = database.frame_count();
  index->dims = n;
  index->components = std::min<std::size_t>(kPcaComponents, n);
  // Mean and covariance in double: hundreds of thousands of rows.
  std::vector<double> mean(n, 0.0), cov(n * n, 0.0);
  for (std::uint32_t f = 0; f < frames; ++f) {
    for (std::size_t d = 0; d < n; ++d) mean[d] += database.row(f)[d];
  }
  for (double& m : mean) m /= double(frames);
  std::vector<double> centred(n);
  for (std::uint32_t f = 0; f < frames; ++f) {
    for (std::size_t d = 0; d < n; ++d) centred[d] = database.row(f)[d] - mean[d];
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i; j < n; ++j) cov[i * n + j] += centred[i] * centred[j];
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < i; ++j) cov[i * n + j] = cov[j * n + i];
  }
  std::vector<double> values, vectors;
  symmetric_eigen(std::move(cov), n, values, vectors);
  index->mean.assign(mean.begin(), mean.end());
  index->axes.assign(vectors.begin(), vectors.begin() + static_cast<std::ptrdiff_t>(index->components * n));
  index->rows.dims = index->components;
  index->rows.values.resize(frames * index->components);
  for (std::uint32_t f = 0; f < frames; ++f) {
    index->project(database.row(f).data(), &index->rows.values[f * index->components]);
  }
  index->tree = std::make_unique<Tree>(index->components, index->rows,
                                       nanoflann::KDTreeSingleIndexAdaptorParams(kKdTreeLeafRows));
  return index;
}

namespace {

class PcaKdTree final : public PeerBackend {
 public:
  PcaKdTree(const Database& database, std::shared_ptr<PcaKdTreeIndex> index, std::uint32_t candidates)
      : PeerBackend(database, "pca-kdtree" + std::to_string(candidates)),
        index_(std::move(index)),
        candidates_(std::min(candidates, database.frame_count())),
        channel_end_(channel_ends(database)) {}

  bool exact() const override { return false; }
  std::size_t index_bytes() const override {
    Tree& tree = *index_->tree;
    // The tree's nodes and its row index array, the projections, the axes.
    return tree.usedMemory(tree) + index_->rows.values.size() * sizeof(float) +
           (index_->axes.size() + index_->mean.size()) * sizeof(float);
  }

  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override {
    MMVK_TRY(check_plain_batch(database_, batch, k, out, name()));
    const std::size_t dims = database_.dims();
    projected_.resize(index_->components);
    ids_.resize(candidates_);
    distances_.resize(candidates_);
    TopK best(k);
    for (std::size_t q = 0; q < batch.size; ++q) {
      const float* query = &batch.features[q * dims];
      index_->project(query, projected_.data());
      const std::size_t found = index_->tree->knnSearch(projected_.data(), candidates_, ids_.data(), distances_.data());
      for (std::size_t c = 0; c < found; ++c) best.offer(ids_[c], plain_cost(database_.row(ids_[c]).data(), query, channel_end_));
      best.write(out.subspan(q * k, k));
      stats_.rows_evaluated += found;
    }
    stats_.queries += batch.size;
    return Status{};
  }

 private:
  std::shared_ptr<PcaKdTreeIndex> index_;
  std::uint32_t candidates_;
  std::vector<std::uint32_t> channel_end_;
  std::vector<float> projected_, distances_;
  std::vector<std::uint32_t> ids_;
};

}  // namespace

Result<std::unique_ptr<PeerBackend>> make_pca_kdtree(const Database& database, std::shared_ptr<PcaKdTreeIndex> index,
                                                     std::uint32_t candidates) {
  if (!index || !index->tree || index->rows.kdtree_get_point_count() != database.frame_count()) {
    return make_error("pca-kdtree: the index was not built from this database");
  }
  if (candidates == 0) return make_error("pca-kdtree: candidates must be >= 1");
  return std::unique_ptr<PeerBackend>(std::make_unique<PcaKdTree>(database, std::move(index), candidates));
}

}  // namespace mmvk::peers
