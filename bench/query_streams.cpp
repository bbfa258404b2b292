#include "query_streams.hpp"

#include <algorithm>
#include <cmath>

namespace mmvk::bench {

namespace {

// splitmix64: a tiny generator whose output is the same on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  std::uint32_t below(std::uint32_t n) { return static_cast<std::uint32_t>(uniform() * n); }
  double gaussian() {  // Box-Muller
    const double u = std::max(uniform(), 1e-300);
    return std::sqrt(-2.0 * std::log(u)) * std::cos(6.283185307179586 * uniform());
  }

 private:
  std::uint64_t state_;
};

}  // namespace

std::string_view query_stream_name(QueryStream stream) {
  switch (stream) {
    case QueryStream::Continue: return "continue";
    case QueryStream::Transition: return "transition";
    case QueryStream::Uniform: return "uniform";
  }
  return "unknown";
}

std::vector<float> make_queries(const Database& database, QueryStream stream, std::size_t count, std::uint64_t seed) {
  const std::uint32_t dims = database.dims();
  const std::uint32_t frames = database.frame_count();
  std::vector<float> queries(count * dims);
  Random random(seed);
  std::vector<float> lo(dims, INFINITY), hi(dims, -INFINITY);
  if (stream == QueryStream::Uniform) {
    for (std::uint32_t f = 0; f < frames; ++f) {
      for (std::uint32_t d = 0; d < dims; ++d) {
        lo[d] = std::min(lo[d], database.row(f)[d]);
        hi[d] = std::max(hi[d], database.row(f)[d]);
      }
    }
  }
  std::vector<bool> trajectory_dim(dims, false);
  for (std::size_t c = 0; c < database.schema().channels.size(); ++c) {
    const FeatureChannel& channel = database.schema().channels[c];
    const std::uint32_t offset = database.schema().offset(c);
    for (std::uint32_t d = 0; d < channel.dims(); ++d) trajectory_dim[offset + d] = uses_trajectory_offsets(channel.kind);
  }
  for (std::size_t q = 0; q < count; ++q) {
    float* out = &queries[q * dims];
    switch (stream) {
      case QueryStream::Continue: {
        const auto row = database.row(random.below(frames));
        // Noise of 0.1 normalized units: about a tenth of a channel's spread.
        for (std::uint32_t d = 0; d < dims; ++d) out[d] = row[d] + static_cast<float>(0.1 * random.gaussian());
        break;
      }
      case QueryStream::Transition: {
        const auto pose = database.row(random.below(frames));
        const auto trajectory = database.row(random.below(frames));
        for (std::uint32_t d = 0; d < dims; ++d) out[d] = trajectory_dim[d] ? trajectory[d] : pose[d];
        break;
      }
      case QueryStream::Uniform:
        for (std::uint32_t d = 0; d < dims; ++d) out[d] = lo[d] + static_cast<float>(random.uniform()) * (hi[d] - lo[d]);
        break;
    }
  }
  return queries;
}

}  // namespace mmvk::bench
