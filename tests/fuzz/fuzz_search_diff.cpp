// libFuzzer target, differential: on any database that loads (with the
// header repaired, as fuzz_mmdb_load's repair variant), every exact CPU
// backend of the registry (all but the *-nprobe ones) must return what the
// reference returns, bit for bit, or fail the same way.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "mmvk/search/backends.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "repair_mmdb.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The first 8 bytes seed the query; the rest is the database.
  if (size < 8) return 0;
  std::uint64_t seed = 0;
  std::memcpy(&seed, data, 8);
  std::string bytes(reinterpret_cast<const char*>(data) + 8, size - 8);
  mmvk::fuzz::repair_mmdb(bytes);
  mmvk::Result<mmvk::Database> db = mmvk::deserialize_database(bytes, "fuzz.mmdb");
  if (!db.ok() || db->frame_count() == 0 || db->frame_count() > 4096) return 0;
  // Queries: two database rows shifted by seed-derived offsets.
  const std::uint32_t dims = db->dims();
  std::vector<float> queries(2 * std::size_t{dims});
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const std::uint32_t frame = static_cast<std::uint32_t>((seed >> (i % 32)) % db->frame_count());
    queries[i] = db->row(frame)[i % dims] + static_cast<float>(static_cast<int>((seed >> (i % 48)) & 0xff) - 128) / 64.0f;
  }
  const std::uint32_t k = 1 + static_cast<std::uint32_t>(seed % 4);
  const mmvk::QueryBatch batch{queries, {}, 2};
  std::vector<mmvk::Match> expected(2 * k);
  const mmvk::BackendRegistry registry = mmvk::cpu_backends();
  mmvk::ThreadPool pool(2);
  mmvk::BackendSpec spec;
  spec.pool = &pool;
  spec.kmeans.clusters = 4;
  spec.name = "reference";
  mmvk::Result<std::unique_ptr<mmvk::SearchBackend>> reference = registry.make(spec, *db);
  if (!reference.ok()) __builtin_trap();  // the reference accepts any database that loads
  const mmvk::Status reference_status = (*reference)->search(batch, k, expected);
  for (const mmvk::BackendEntry& entry : registry.entries()) {
    if (entry.name == "reference" || entry.uses_nprobe) continue;
    spec.name = entry.name;
    mmvk::Result<std::unique_ptr<mmvk::SearchBackend>> backend = registry.make(spec, *db);
    if (!backend.ok()) __builtin_trap();
    std::vector<mmvk::Match> got(2 * k);
    const mmvk::Status status = (*backend)->search(batch, k, got);
    if (status.ok() != reference_status.ok()) __builtin_trap();
    if (!status.ok()) continue;
    for (std::size_t i = 0; i < got.size(); ++i) {
      if (got[i].frame != expected[i].frame) __builtin_trap();
      if (std::memcmp(&got[i].cost, &expected[i].cost, sizeof(float)) != 0) __builtin_trap();
    }
  }
  return 0;
}
