// Cluster table files. Layout (little-endian, no padding):
//   char[8]  magic "MMVKCLT\0"
//   u32      version (1)
//   u32      reserved (0)
//   u64      database_hash
//   u32      dims, cluster_count, channel_count, frame_count
//   f32      centroids[cluster_count x dims]
//   u32      offsets[cluster_count + 1]
//   u32      members[frame_count]
//   f32      box_min[cluster_count x dims], box_max[cluster_count x dims]
//   f32      min_multiplier[cluster_count], min_bias[cluster_count]
//   u64      tag_union[cluster_count], tag_intersection[cluster_count]
//   u32      flags_intersection[cluster_count]
//   f32      channel_radius[cluster_count x channel_count]
//   u64      FNV-1a checksum of every byte before it
// Loading checks the structure only; validate_cluster_table() then checks the
// table against the database it is used with.
#include <array>
#include <bit>
#include <cstring>
#include <string>

#include "mmvk/common/file_io.hpp"
#include "mmvk/common/hash.hpp"
#include "mmvk/clusters/cluster_table.hpp"

namespace mmvk {

namespace {

static_assert(std::endian::native == std::endian::little, "cluster table files are little-endian");

constexpr char kMagic[8] = {'M', 'M', 'V', 'K', 'C', 'L', 'T', '\0'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderSize = 8 + 4 + 4 + 8 + 4 * 4;

template <class T>
void put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <class T>
void put_array(std::string& out, const std::vector<T>& values) {
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}
  template <class T>
  T get() {
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  template <class T>
  std::vector<T> get_array(std::size_t count) {
    std::vector<T> values(count);
    // An empty vector's data() may be null, and memcpy from or to null is
    // undefined even for zero bytes.
    if (count == 0) return values;
    std::memcpy(values.data(), bytes_.data() + pos_, count * sizeof(T));
    pos_ += count * sizeof(T);
    return values;
  }

 private:
  std::string_view bytes_;
  std::size_t pos_ = 0;
};

}  // namespace

Status save_cluster_table(const ClusterTable& t, const std::filesystem::path& path) {
  const std::size_t kd = std::size_t{t.cluster_count} * t.dims;
  if (t.centroids.size() != kd || t.offsets.size() != t.cluster_count + std::size_t{1} || t.box_min.size() != kd ||
      t.box_max.size() != kd || t.min_multiplier.size() != t.cluster_count || t.min_bias.size() != t.cluster_count ||
      t.tag_union.size() != t.cluster_count || t.tag_intersection.size() != t.cluster_count ||
      t.flags_intersection.size() != t.cluster_count ||
      t.channel_radius.size() != std::size_t{t.cluster_count} * t.channel_count || t.members.size() > 0xFFFFFFFFu) {
    return make_error(path.string() + ": cannot save an inconsistent cluster table (array sizes do not match its counts)");
  }
  std::string out;
  out.append(kMagic, sizeof(kMagic));
  put(out, kVersion);
  put(out, std::uint32_t{0});
  put(out, t.database_hash);
  put(out, t.dims);
  put(out, t.cluster_count);
  put(out, t.channel_count);
  put(out, static_cast<std::uint32_t>(t.members.size()));
  put_array(out, t.centroids);
  put_array(out, t.offsets);
  put_array(out, t.members);
  put_array(out, t.box_min);
  put_array(out, t.box_max);
  put_array(out, t.min_multiplier);
  put_array(out, t.min_bias);
  put_array(out, t.tag_union);
  put_array(out, t.tag_intersection);
  put_array(out, t.flags_intersection);
  put_array(out, t.channel_radius);
  Hasher hasher;
  hasher.add_bytes(out.data(), out.size());
  put(out, hasher.digest());
  return write_file_atomically(path, out);
}

Result<ClusterTable> load_cluster_table(const std::filesystem::path& path) {
  Result<std::string> file = read_file(path);
  if (!file.ok()) return file.error();
  const std::string& bytes = *file;
  const std::string where = path.string() + ": ";
  if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return make_error(where + "not a cluster table file (bad magic)");
  }
  if (bytes.size() < kHeaderSize + 8) {
    return make_error(where + "truncated cluster table (" + std::to_string(bytes.size()) + " bytes)");
  }
  Reader reader(bytes);
  reader.get<std::array<char, 8>>();
  const auto version = reader.get<std::uint32_t>();
  if (version != kVersion) {
    return make_error(where + "cluster table version " + std::to_string(version) + " is not supported (expected " +
                      std::to_string(kVersion) + ")");
  }
  reader.get<std::uint32_t>();
  ClusterTable t;
  t.database_hash = reader.get<std::uint64_t>();
  t.dims = reader.get<std::uint32_t>();
  t.cluster_count = reader.get<std::uint32_t>();
  t.channel_count = reader.get<std::uint32_t>();
  const auto frames = reader.get<std::uint32_t>();
  if (t.cluster_count == 0) return make_error(where + "cluster_count is 0 (a table needs at least one cluster)");
  // Every array element takes at least 4 bytes, so no count, nor the
  // products clusters x dims and clusters x channels, can exceed a quarter
  // of the file. Checked first, by division: the size formula below
  // multiplies counts, and a header of large counts once wrapped it around
  // to the file's own size (a fuzz finding, tests/corpus/fuzz_cluster_table).
  const std::uint64_t quarter = bytes.size() / 4;
  if (t.cluster_count > quarter || frames > quarter || t.dims > quarter || t.channel_count > quarter ||
      (t.dims != 0 && t.cluster_count > quarter / t.dims) ||
      (t.channel_count != 0 && t.cluster_count > quarter / t.channel_count)) {
    return make_error(where + "header counts (" + std::to_string(t.cluster_count) + " clusters, " +
                      std::to_string(t.dims) + " dims, " + std::to_string(t.channel_count) + " channels, " +
                      std::to_string(frames) + " frames) need more than the file's " +
                      std::to_string(bytes.size()) + " bytes (truncated or corrupted)");
  }
  // With the counts so bounded the sum below stays far below 2^64.
  const std::uint64_t k = t.cluster_count;
  const std::uint64_t kd = k * t.dims;
  const std::uint64_t expected = kHeaderSize + kd * 4 + (k + 1) * 4 + std::uint64_t{frames} * 4 + kd * 8 + k * 8 +
                                 k * 16 + k * 4 + k * t.channel_count * 4 + 8;
  if (bytes.size() != expected) {
    return make_error(where + "file has " + std::to_string(bytes.size()) + " bytes, its header implies " +
                      std::to_string(expected) + " (truncated or corrupted)");
  }
  Hasher hasher;
  hasher.add_bytes(bytes.data(), bytes.size() - 8);
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (stored != hasher.digest()) return make_error(where + "checksum mismatch (the file is corrupted)");
  t.centroids = reader.get_array<float>(kd);
  t.offsets = reader.get_array<std::uint32_t>(k + 1);
  t.members = reader.get_array<std::uint32_t>(frames);
  t.box_min = reader.get_array<float>(kd);
  t.box_max = reader.get_array<float>(kd);
  t.min_multiplier = reader.get_array<float>(k);
  t.min_bias = reader.get_array<float>(k);
  t.tag_union = reader.get_array<TagMask>(k);
  t.tag_intersection = reader.get_array<TagMask>(k);
  t.flags_intersection = reader.get_array<std::uint32_t>(k);
  t.channel_radius = reader.get_array<float>(k * t.channel_count);
  return t;
}

}  // namespace mmvk
