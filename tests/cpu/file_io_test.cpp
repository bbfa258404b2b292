// The public file I/O (mmvk/file_io.hpp): float32 row files round-trip bit
// for bit, and wrong sizes are errors naming the file.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "mmvk/file_io.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

TEST(FileIo, FloatRowsRoundTripBitForBit) {
  const fs::path dir = test::make_temp_dir();
  const std::vector<float> values = {0.0f, -0.0f, 1.5f, -3.25e-20f, std::numeric_limits<float>::infinity(),
                                     std::numeric_limits<float>::denorm_min()};
  ASSERT_TRUE(write_f32_rows(dir / "rows.f32", values).ok());
  Result<std::string> bytes = read_file(dir / "rows.f32");
  ASSERT_TRUE(bytes.ok()) << bytes.message();
  ASSERT_EQ(bytes->size(), values.size() * 4);
  // Little-endian on disk whatever the host: 1.5f is 0x3FC00000.
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[8 + 3]), 0x3F);
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[8 + 2]), 0xC0);
  for (const std::uint32_t cols : {1u, 2u, 3u, 6u}) {
    Result<std::vector<float>> read = read_f32_rows(dir / "rows.f32", cols);
    ASSERT_TRUE(read.ok()) << read.message();
    ASSERT_EQ(read->size(), values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      EXPECT_EQ(std::bit_cast<std::uint32_t>((*read)[i]), std::bit_cast<std::uint32_t>(values[i])) << i;
    }
  }
  EXPECT_TRUE(read_f32_rows(dir / "rows.f32", 3, 2).ok());
}

TEST(FileIo, FloatRowSizesAreCheckedAndNamed) {
  const fs::path dir = test::make_temp_dir();
  ASSERT_TRUE(write_f32_rows(dir / "six.f32", std::vector<float>(6, 1.0f)).ok());
  ASSERT_TRUE(write_file_atomically(dir / "odd.f32", std::string(10, '\0')).ok());
  ASSERT_TRUE(write_file_atomically(dir / "empty.f32", "").ok());
  auto expect_error = [](const Result<std::vector<float>>& result, const std::string& needle) {
    ASSERT_FALSE(result.ok()) << needle;
    EXPECT_NE(result.message().find(needle), std::string::npos) << result.message();
  };
  expect_error(read_f32_rows(dir / "six.f32", 4), "six.f32");            // not whole rows
  expect_error(read_f32_rows(dir / "odd.f32", 1), "odd.f32");            // not whole floats
  expect_error(read_f32_rows(dir / "empty.f32", 3), "empty.f32");        // no rows
  expect_error(read_f32_rows(dir / "six.f32", 3, 3), "expected 3 rows");  // another row count
  expect_error(read_f32_rows(dir / "six.f32", 0), "six.f32");            // no columns
  expect_error(read_f32_rows(dir / "missing.f32", 3), "missing.f32");    // unreadable
  // An expected count of zero rows accepts the empty file.
  Result<std::vector<float>> none = read_f32_rows(dir / "empty.f32", 3, 0);
  ASSERT_TRUE(none.ok()) << none.message();
  EXPECT_TRUE(none->empty());
}

TEST(FileIo, CodecAppendsAndDecodes) {
  std::string bytes = "head";
  const std::vector<float> values = {1.0f, -2.0f, 0.5f};
  append_f32_le(bytes, values);
  ASSERT_EQ(bytes.size(), 4 + values.size() * 4);
  std::vector<float> decoded(values.size());
  decode_f32_le(std::string_view(bytes).substr(4), decoded);
  EXPECT_EQ(decoded, values);
}

}  // namespace
}  // namespace mmvk
