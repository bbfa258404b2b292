// The .mmdb file: bit-exact round trip, and every kind of damage rejected
// with its own message naming the file.
#include <gtest/gtest.h>

#include <bit>
#include <csignal>
#include <cstring>
#include <fstream>
#include <random>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mmvk/common/hash.hpp"
#include "mmvk/database/database_io.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

// `units`: the clips record the import's metres per unit (a version 4 file).
Database make_database(bool units = false) {
  DatabaseParts parts;
  parts.schema = default_schema();
  parts.schema.channels[2].weight = 1.0f / 3.0f;
  parts.schema.channels[5].normalization = Normalization::MinMax;
  parts.fps = 30.0f;
  const std::uint32_t dims = parts.schema.dims();
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> uniform(-2.0f, 2.0f);
  for (std::uint32_t d = 0; d < dims; ++d) parts.normalization.push_back({uniform(rng), 0.5f + std::abs(uniform(rng))});
  parts.tag_names = {"walk", "run", "turn"};
  const std::uint32_t lengths[] = {40, 1, 73};
  std::uint32_t first = 0;
  for (std::uint32_t c = 0; c < 3; ++c) {
    Clip clip;
    clip.name = "clip" + std::to_string(c);
    clip.source = "/data/clip" + std::to_string(c) + ".bvh";
    clip.tags = c == 1 ? 0 : (TagMask{1} << c) | 1;
    clip.loop = c == 2;
    clip.mirrored = c == 1;
    clip.cost_multiplier = 1.0f + 0.25f * float(c);
    clip.cost_bias = -0.125f * float(c);
    clip.first_frame = first;
    clip.frame_count = lengths[c];
    clip.metres_per_unit = units ? (c == 1 ? 0.01f : 0.05644f) : 0.0f;
    first += lengths[c];
    parts.clips.push_back(clip);
  }
  for (std::uint32_t f = 0; f < first; ++f) parts.frame_flags.push_back(f % 7 == 0 ? kFrameDoNotUse : f % 11 == 0 ? kFrameEdgeExcluded | kFrameBlockTransition : 0);
  for (std::uint32_t i = 0; i < first * dims; ++i) parts.features.push_back(uniform(rng) * 1e3f);
  Result<Database> db = Database::create(std::move(parts));
  EXPECT_TRUE(db.ok()) << db.message();
  return std::move(db).value();
}

void expect_identical(const Database& a, const Database& b) {
  EXPECT_EQ(schema_to_json(a.schema()), schema_to_json(b.schema()));
  EXPECT_EQ(std::bit_cast<std::uint32_t>(a.fps()), std::bit_cast<std::uint32_t>(b.fps()));
  ASSERT_EQ(a.features().size(), b.features().size());
  EXPECT_EQ(0, std::memcmp(a.features().data(), b.features().data(), a.features().size_bytes()));
  ASSERT_EQ(a.normalization().size(), b.normalization().size());
  EXPECT_EQ(0, std::memcmp(a.normalization().data(), b.normalization().data(), a.normalization().size_bytes()));
  EXPECT_TRUE(std::equal(a.frame_flags().begin(), a.frame_flags().end(), b.frame_flags().begin(), b.frame_flags().end()));
  EXPECT_TRUE(std::equal(a.tag_names().begin(), a.tag_names().end(), b.tag_names().begin(), b.tag_names().end()));
  ASSERT_EQ(a.clips().size(), b.clips().size());
  for (std::size_t c = 0; c < a.clips().size(); ++c) {
    const Clip& x = a.clips()[c];
    const Clip& y = b.clips()[c];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.source, y.source);
    EXPECT_EQ(x.tags, y.tags);
    EXPECT_EQ(x.loop, y.loop);
    EXPECT_EQ(x.mirrored, y.mirrored);
    EXPECT_EQ(x.cost_multiplier, y.cost_multiplier);
    EXPECT_EQ(x.cost_bias, y.cost_bias);
    EXPECT_EQ(x.first_frame, y.first_frame);
    EXPECT_EQ(x.frame_count, y.frame_count);
    EXPECT_EQ(x.metres_per_unit, y.metres_per_unit);
  }
  EXPECT_EQ(a.content_hash(), b.content_hash());
}

std::string load_error(const std::string& bytes) {
  Result<Database> db = deserialize_database(bytes, "db.mmdb");
  EXPECT_FALSE(db.ok());
  return db.ok() ? std::string() : db.message();
}

void put_u32(std::string& bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

// Recomputes the trailing checksum after a deliberate edit.
void reseal(std::string& bytes) {
  Hasher hasher;
  hasher.add_bytes(bytes.data(), bytes.size() - 8);
  const std::uint64_t sum = hasher.digest();
  for (int i = 0; i < 8; ++i) bytes[bytes.size() - 8 + i] = static_cast<char>((sum >> (8 * i)) & 0xFF);
}

TEST(DatabaseIo, RoundTripIsBitExact) {
  const Database db = make_database();
  const std::string bytes = serialize_database(db);
  Result<Database> back = deserialize_database(bytes, "db.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  expect_identical(db, *back);
  EXPECT_EQ(serialize_database(*back), bytes);

  const auto dir = test::make_temp_dir();
  ASSERT_TRUE(save_database(db, dir / "db.mmdb").ok());
  Result<Database> loaded = load_database(dir / "db.mmdb");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  expect_identical(db, *loaded);
}

TEST(DatabaseIo, ImportUnitsMakeAVersion4FileAndRoundTrip) {
  const Database without = make_database();
  EXPECT_EQ(serialize_database(without)[8], char(2)) << "nothing newer to record: older builds read it";
  const Database with = make_database(true);
  const std::string bytes = serialize_database(with);
  EXPECT_EQ(bytes[8], char(4));
  Result<Database> back = deserialize_database(bytes, "db.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  expect_identical(with, *back);
  EXPECT_EQ(back->clips()[1].metres_per_unit, 0.01f);
  EXPECT_EQ(serialize_database(*back), bytes);
  EXPECT_EQ(back->content_hash(), without.content_hash()) << "units do not change what a search sees";
  for (std::size_t size = 0; size < bytes.size(); size += 7) {
    EXPECT_FALSE(deserialize_database(std::string_view(bytes).substr(0, size), "db.mmdb").ok()) << size;
  }
}

TEST(DatabaseIo, GaitBandsMakeAVersion7FileAndRoundTrip) {
  const Database without = make_database();
  DatabaseParts parts = without.parts();
  for (std::string_view name : kGaitTagNames) parts.tag_names.emplace_back(name);
  parts.gait_bands.emplace().run_from_mps = 3.5f;
  Result<Database> with = Database::create(parts);
  ASSERT_TRUE(with.ok()) << with.message();
  const std::string bytes = serialize_database(*with);
  EXPECT_EQ(bytes[8], char(7));
  Result<Database> back = deserialize_database(bytes, "db.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  ASSERT_NE(back->gait_bands(), nullptr);
  EXPECT_EQ(back->gait_bands()->run_from_mps, 3.5f);
  EXPECT_EQ(back->gait_bands()->walk_from_mps, GaitBandParams{}.walk_from_mps);
  EXPECT_EQ(serialize_database(*back), bytes);
  for (std::size_t size = 0; size < bytes.size(); size += 7) {
    EXPECT_FALSE(deserialize_database(std::string_view(bytes).substr(0, size), "db.mmdb").ok()) << size;
  }
  // Parameters the build would refuse, or bands without their tags, are refused on load too.
  parts.gait_bands->run_from_mps = 1.0f;
  EXPECT_NE(Database::create(parts).message().find("gait_bands.run_from_mps: must be above jog_from_mps"),
            std::string::npos);
  DatabaseParts untagged = without.parts();
  untagged.gait_bands.emplace();
  EXPECT_NE(Database::create(untagged).message().find("the tag 'gait:stand' is missing"), std::string::npos);
}

TEST(DatabaseIo, CrowdSettingsMakeAVersion6FileAndRoundTrip) {
  const Database without = make_database();
  DatabaseParts parts = without.parts();
  parts.crowd_settings = R"({"correction_half_life":0.07})";
  Result<Database> with = Database::create(std::move(parts));
  ASSERT_TRUE(with.ok()) << with.message();
  const std::string bytes = serialize_database(*with);
  EXPECT_EQ(bytes[8], char(6));
  Result<Database> back = deserialize_database(bytes, "db.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(back->crowd_settings(), R"({"correction_half_life":0.07})");
  EXPECT_EQ(serialize_database(*back), bytes);
  EXPECT_EQ(back->content_hash(), without.content_hash()) << "crowd settings do not change what a search sees";
  EXPECT_TRUE(deserialize_database(serialize_database(without), "db.mmdb")->crowd_settings().empty());
  for (std::size_t size = 0; size < bytes.size(); size += 7) {
    EXPECT_FALSE(deserialize_database(std::string_view(bytes).substr(0, size), "db.mmdb").ok()) << size;
  }
}

TEST(DatabaseIo, TruncatedFilesAreRejectedAtEveryLength) {
  const std::string bytes = serialize_database(make_database());
  for (std::size_t length = 0; length < bytes.size(); length += (length < 128 || length + 128 > bytes.size()) ? 1 : 97) {
    SCOPED_TRACE(length);
    const std::string message = load_error(bytes.substr(0, length));
    EXPECT_NE(message.find("db.mmdb: truncated"), std::string::npos) << message;
  }
}

TEST(DatabaseIo, BitFlipsAreRejected) {
  const std::string bytes = serialize_database(make_database());
  for (std::size_t at = 0; at < bytes.size(); at += (at < 64 || at + 64 > bytes.size()) ? 1 : 13) {
    for (int bit : {0, 7}) {
      SCOPED_TRACE(testing::Message() << "byte " << at << " bit " << bit);
      std::string damaged = bytes;
      damaged[at] = static_cast<char>(damaged[at] ^ (1 << bit));
      const std::string message = load_error(damaged);
      EXPECT_NE(message.find("db.mmdb: "), std::string::npos) << message;
      if (at >= kDatabaseHeaderBytes) {
        EXPECT_NE(message.find("checksum mismatch"), std::string::npos) << message;
      }
    }
  }
}

TEST(DatabaseIo, WrongMagicAndWrongVersionHaveTheirOwnMessages) {
  const std::string bytes = serialize_database(make_database());
  std::string other = bytes;
  other[0] = 'X';
  EXPECT_NE(load_error(other).find("db.mmdb: not an mmvk database (wrong magic)"), std::string::npos);
  EXPECT_NE(load_error("HIERARCHY\nROOT Hips\n{\n}\n").find("not an mmvk database"), std::string::npos);

  std::string newer = bytes;
  put_u32(newer, 8, kDatabaseFormatVersion + 1);
  reseal(newer);
  EXPECT_NE(load_error(newer).find("db.mmdb: unsupported mmvk database version " + std::to_string(kDatabaseFormatVersion + 1)),
            std::string::npos);
  put_u32(newer, 8, 0);
  EXPECT_NE(load_error(newer).find("unsupported mmvk database version 0"), std::string::npos);
}

TEST(DatabaseIo, HostileSizesWithAValidChecksumAreRejected) {
  const Database db = make_database();
  const std::string bytes = serialize_database(db);
  // The tag count follows the schema string, fps, dims and the normalization.
  const std::size_t schema_bytes = schema_to_json(db.schema()).size();
  const std::size_t tag_count_at = kDatabaseHeaderBytes + 4 + schema_bytes + 4 + 4 + 8 * db.dims();
  ASSERT_EQ(bytes[tag_count_at], 3);
  for (std::uint32_t hostile : {4u, 65u, 0xFFFFFFFFu}) {
    std::string damaged = bytes;
    put_u32(damaged, tag_count_at, hostile);
    reseal(damaged);
    const std::string message = load_error(damaged);
    EXPECT_NE(message.find("db.mmdb: corrupt mmvk database payload"), std::string::npos) << message;
  }
  // A schema string length past the end.
  std::string damaged = bytes;
  put_u32(damaged, kDatabaseHeaderBytes, 0x7FFFFFFFu);
  reseal(damaged);
  EXPECT_NE(load_error(damaged).find("corrupt mmvk database payload: schema"), std::string::npos);
  // A clip range that no longer covers the frames: caught by Database::create.
  // Tags "walk", "run", "turn", then the clip count and clip 0: name
  // "clip0", source "/data/clip0.bvh", tags, loop, mirrored, multiplier,
  // bias, first frame, frame count.
  const std::size_t clip_count_at = tag_count_at + 4 + (4 + 4) + (4 + 3) + (4 + 4);
  ASSERT_EQ(bytes[clip_count_at], 3);
  const std::size_t frame_count_at = clip_count_at + 4 + (4 + 5) + (4 + 15) + 8 + 1 + 1 + 4 + 4 + 4;
  ASSERT_EQ(bytes[frame_count_at], 40);
  damaged = bytes;
  put_u32(damaged, frame_count_at, 39);
  reseal(damaged);
  const std::string message = load_error(damaged);
  EXPECT_NE(message.find("db.mmdb: invalid mmvk database: database: clip 1"), std::string::npos) << message;
}

TEST(DatabaseIo, MissingFileIsNamed) {
  const auto dir = test::make_temp_dir();
  Result<Database> db = load_database(dir / "absent.mmdb");
  ASSERT_FALSE(db.ok());
  EXPECT_NE(db.message().find("absent.mmdb"), std::string::npos);
}

TEST(DatabaseIo, FailedWriteLeavesTheOldFileIntact) {
  const auto dir = test::make_temp_dir();
  const auto path = dir / "db.mmdb";
  const Database db = make_database();
  ASSERT_TRUE(save_database(db, path).ok());
  std::ifstream before_in(path, std::ios::binary);
  const std::string before((std::istreambuf_iterator<char>(before_in)), std::istreambuf_iterator<char>());
  DatabaseParts parts = db.parts();
  parts.fps = 60.0f;
  Result<Database> other = Database::create(std::move(parts));
  ASSERT_TRUE(other.ok());
  // The write fails half-way: a child process may write files of at most
  // 1000 bytes (EFBIG instead of SIGXFSZ), which holds even for root.
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{1000, 1000};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(10);
    const Status saved = save_database(*other, path);
    ::_exit(saved.ok() ? 0 : (saved.message().find("db.mmdb") != std::string::npos ? 3 : 11));
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 3) << "the save should have failed, naming the file";
  // Only the old file is left: the temp file was removed.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
  std::ifstream after_in(path, std::ios::binary);
  const std::string after((std::istreambuf_iterator<char>(after_in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(before, after);
  Result<Database> loaded = load_database(path);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(loaded->fps(), 30.0f);
}

}  // namespace
}  // namespace mmvk
