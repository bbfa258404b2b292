// libFuzzer target: the .mmdb loader on arbitrary bytes. Built twice: as is,
// and with MMVK_FUZZ_REPAIR, which rewrites the header's size and checksum
// fields so that mutations reach the section parsers behind them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "mmvk/database/database_io.hpp"
#include "mmvk/search/search.hpp"

#if defined(MMVK_FUZZ_REPAIR)
#include "repair_mmdb.hpp"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
#if defined(MMVK_FUZZ_REPAIR)
  mmvk::fuzz::repair_mmdb(bytes);
#endif
  mmvk::Result<mmvk::Database> db = mmvk::deserialize_database(bytes, "fuzz.mmdb");
  if (!db.ok()) return 0;
  // A database that loads must survive a round trip and a frame_cost call.
  const std::string again = mmvk::serialize_database(*db);
  mmvk::Result<mmvk::Database> reloaded = mmvk::deserialize_database(again, "fuzz.mmdb (again)");
  if (!reloaded.ok()) __builtin_trap();
  if (db->frame_count() > 0) {
    const std::vector<float> query(db->dims(), 0.0f);
    (void)mmvk::frame_cost(*db, 0, query, mmvk::QueryParams{});
  }
  return 0;
}
