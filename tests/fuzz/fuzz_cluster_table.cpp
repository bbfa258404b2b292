// libFuzzer target: the cluster table loader (its trailing checksum repaired
// so that mutations reach the structure checks), then validation against a
// small fixed database.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "mmvk/common/hash.hpp"
#include "fixed_database.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "temp_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (bytes.size() >= 16) {
    mmvk::Hasher hasher;
    hasher.add_bytes(bytes.data(), bytes.size() - 8);
    const std::uint64_t digest = hasher.digest();
    std::memcpy(bytes.data() + bytes.size() - 8, &digest, 8);
  }
  mmvk::Result<mmvk::ClusterTable> table = mmvk::load_cluster_table(mmvk::fuzz::write_scratch(bytes, ".mmkc"));
  if (table.ok()) (void)mmvk::validate_cluster_table(*table, mmvk::fuzz::fixed_database());
  return 0;
}
