// libFuzzer target: manifest and schema JSON. The first byte picks the
// parser, the rest is the text.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mmvk/features/feature_schema.hpp"
#include "mmvk/database/manifest.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1) {
    // A nonexistent base folder: schema or clip files named by the input are
    // not found instead of read from wherever the fuzzer runs.
    (void)mmvk::parse_manifest_json(text, "fuzz.json", "/nonexistent-mmvk-fuzz");
  } else {
    mmvk::Result<mmvk::FeatureSchema> schema = mmvk::parse_schema_json(text, "fuzz.json");
    if (schema.ok()) (void)schema->validate();
  }
  return 0;
}
