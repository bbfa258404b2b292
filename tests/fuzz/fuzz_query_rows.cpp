// libFuzzer target: the query reader (a float32 row file) and validation of
// what it read as a search batch against the small fixed database (non-finite
// values, overflowing costs).
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "fixed_database.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/search/search.hpp"
#include "temp_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const mmvk::Database& db = mmvk::fuzz::fixed_database();
  mmvk::Result<std::vector<float>> rows = mmvk::read_f32_rows(mmvk::fuzz::write_scratch(bytes, ".f32"), db.dims());
  if (!rows.ok()) return 0;
  const std::size_t count = rows->size() / db.dims();
  std::vector<mmvk::Match> out(count);
  (void)mmvk::validate_search(db, mmvk::QueryBatch{*rows, {}, count}, 1, out);
  return 0;
}
