// The BVH parser on hand-written text: the accepted variants, the malformed
// corpus in tests/corpus/bvh/ (each file with its specific error and line),
// and garbage (truncations and byte flips must give an error, never a crash).
#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "mmvk/import/bvh.hpp"
#include "support/test_data.hpp"

namespace {

using mmvk::BvhChannel;
using mmvk::parse_bvh;

// Two joints and an End Site; 9 channels; 2 frames.
const std::string kValid =
    "HIERARCHY\n"
    "ROOT Hips\n"
    "{\n"
    "  OFFSET 0 0 0\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
    "  JOINT Leg\n"
    "  {\n"
    "    OFFSET 0 -10 0\n"
    "    CHANNELS 3 Zrotation Yrotation Xrotation\n"
    "    End Site\n"
    "    {\n"
    "      OFFSET 0 -10 0\n"
    "    }\n"
    "  }\n"
    "}\n"
    "MOTION\n"
    "Frames: 2\n"
    "Frame Time: 0.0333333\n"
    "0 90 0 0 0 0 0 0 0\n"
    "0 90 1 0 0 5 0 0 0\n";

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

void expect_valid_two_frames(const std::string& text) {
  const auto file = parse_bvh(text, "t.bvh");
  ASSERT_TRUE(file.ok()) << file.message();
  ASSERT_EQ(file->joints.size(), 2u);
  EXPECT_EQ(file->joints[0].name, "Hips");
  EXPECT_EQ(file->joints[1].name, "Leg");
  EXPECT_EQ(file->joints[1].parent, 0);
  EXPECT_EQ(file->joints[1].offset, glm::vec3(0.0f, -10.0f, 0.0f));
  EXPECT_TRUE(file->joints[1].has_end_site);
  EXPECT_EQ(file->joints[1].end_site_offset, glm::vec3(0.0f, -10.0f, 0.0f));
  EXPECT_EQ(file->joints[1].first_channel, 6);
  EXPECT_EQ(file->channel_count, 9);
  EXPECT_EQ(file->frame_count, 2);
  ASSERT_EQ(file->values.size(), 18u);
  EXPECT_EQ(file->values[9 + 2], 1.0f);
  EXPECT_EQ(file->values[9 + 5], 5.0f);
}

TEST(BvhParser, ParsesTheBasicLayout) {
  expect_valid_two_frames(kValid);
  const auto file = parse_bvh(kValid, "t.bvh");
  ASSERT_TRUE(file.ok());
  EXPECT_EQ(file->joints[0].channels,
            (std::vector<BvhChannel>{BvhChannel::Xposition, BvhChannel::Yposition, BvhChannel::Zposition,
                                     BvhChannel::Zrotation, BvhChannel::Yrotation, BvhChannel::Xrotation}));
  EXPECT_DOUBLE_EQ(file->frame_time, 0.0333333);
  EXPECT_EQ(file->source, "t.bvh");
}

TEST(BvhParser, AcceptsEveryLineEnding) {
  expect_valid_two_frames(replace_all(kValid, "\n", "\r\n"));
  expect_valid_two_frames(replace_all(kValid, "\n", "\r"));
  // Mixed: CRLF in the hierarchy, LF in the motion section (cgspeed files).
  const std::size_t motion = kValid.find("MOTION");
  expect_valid_two_frames(replace_all(kValid.substr(0, motion), "\n", "\r\n") + kValid.substr(motion));
  // No line break after the last frame.
  expect_valid_two_frames(kValid.substr(0, kValid.size() - 1));
  // A UTF-8 byte order mark.
  expect_valid_two_frames("\xEF\xBB\xBF" + kValid);
}

TEST(BvhParser, AcceptsTabsTrailingBlanksAndBlankLines) {
  std::string text = replace_all(kValid, "  ", "\t");
  text = replace_all(text, "Frames: ", "Frames:\t");
  text = replace_all(text, "Frame Time: ", "Frame Time:\t");
  text = replace_all(text, "Xrotation\n", "Xrotation \n");
  text = replace_all(text, "0 90 ", "\t0\t90  ");
  expect_valid_two_frames("\n\n" + text + "\n\n  \n");
}

TEST(BvhParser, AcceptsNumberVariants) {
  std::string text = replace_all(kValid, "Frame Time: 0.0333333", "Frame Time: .0083333");
  text = replace_all(text, "0 90 1 0 0 5", "-0.0000 9.0e1 1. +0 -2.47945e-15 0.5E+1");
  const auto file = parse_bvh(text, "t.bvh");
  ASSERT_TRUE(file.ok()) << file.message();
  EXPECT_DOUBLE_EQ(file->frame_time, 0.0083333);
  EXPECT_EQ(file->values[9 + 1], 90.0f);
  EXPECT_EQ(file->values[9 + 2], 1.0f);
  EXPECT_FLOAT_EQ(file->values[9 + 4], -2.47945e-15f);
  EXPECT_EQ(file->values[9 + 5], 5.0f);
}

// The motion reader has a fast path for short decimals; whatever path a
// number takes, the float must be the one std::from_chars gives (correctly
// rounded), bit for bit.
TEST(BvhParser, NumbersMatchFromCharsBitForBit) {
  std::mt19937 rng(42);
  std::vector<std::string> numbers;
  for (int i = 0; i < 20000; ++i) {
    std::string number;
    if (rng() % 3 == 0) number += '-';
    const int integer_digits = static_cast<int>(rng() % 5);
    const int fraction_digits = static_cast<int>(rng() % 11);
    for (int d = 0; d < integer_digits; ++d) number += static_cast<char>('0' + rng() % 10);
    if (fraction_digits > 0 || rng() % 2) number += '.';
    for (int d = 0; d < fraction_digits; ++d) number += static_cast<char>('0' + (rng() % 4 == 0 ? 0 : rng() % 10));
    if (rng() % 4 == 0) number += std::string(rng() % 6, '0');  // trailing zeros
    if (number.find_first_of("0123456789") == std::string::npos) number += '7';
    if (rng() % 10 == 0) {
      number += 'e';
      number += std::to_string(static_cast<int>(rng() % 20) - 10);
    }
    numbers.push_back(number);
  }
  for (const char* fixed : {"0", "-0", "-0.0000", "16777216", "16777217", "9999999", "0.0000001", "1.", ".5",
                            "-.5", "+3.25", "0.00833333", "93.3139", "-2.47945e-15", "3.4028234e38", "1e-45",
                            "-375.227000", "88.510500", "1200", "1200.", "12000000", "1234567.0000", "0.0000000001",
                            "100.00000000001", "0.10000000"}) {
    numbers.push_back(fixed);
  }
  std::string text = "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: " +
                     std::to_string(numbers.size()) + "\nFrame Time: 0.01\n";
  for (const std::string& number : numbers) text += number + "\n";
  const auto file = parse_bvh(text, "numbers.bvh");
  ASSERT_TRUE(file.ok()) << file.message();
  ASSERT_EQ(file->values.size(), numbers.size());
  for (std::size_t i = 0; i < numbers.size(); ++i) {
    const std::string& number = numbers[i];
    const char* first = number.data() + (number[0] == '+' ? 1 : 0);
    float expected = 0.0f;
    std::from_chars(first, number.data() + number.size(), expected);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(file->values[i]), std::bit_cast<std::uint32_t>(expected)) << number;
  }
  // Not numbers: a sign after '+', a lone sign or dot, two dots, hex, inf.
  for (const char* bad : {"+-5", "-", ".", "1.2.3", "0x10", "inf", "-nan", "1e", "5,0"}) {
    const std::string one = "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 1\n"
                            "Frame Time: 0.01\n" + std::string(bad) + "\n";
    const auto rejected = parse_bvh(one, "bad.bvh");
    ASSERT_FALSE(rejected.ok()) << bad;
    EXPECT_NE(rejected.message().find("bad.bvh:10: non-numeric token"), std::string::npos) << rejected.message();
  }
}

TEST(BvhParser, AcceptsZeroAndOneFrame) {
  std::string zero = kValid.substr(0, kValid.find("0 90 0")) ;
  zero = replace_all(zero, "Frames: 2", "Frames: 0");
  const auto none = parse_bvh(zero, "zero.bvh");
  ASSERT_TRUE(none.ok()) << none.message();
  EXPECT_EQ(none->frame_count, 0);
  EXPECT_TRUE(none->values.empty());

  std::string one = replace_all(kValid, "Frames: 2", "Frames: 1");
  one = one.substr(0, one.find("0 90 1"));
  const auto single = parse_bvh(one, "one.bvh");
  ASSERT_TRUE(single.ok()) << single.message();
  EXPECT_EQ(single->frame_count, 1);
  EXPECT_EQ(single->values.size(), 9u);
}

TEST(BvhParser, AcceptsSixChannelsOnEveryJointAndStaticJoints) {
  std::string text = replace_all(kValid, "CHANNELS 3 Zrotation Yrotation Xrotation",
                                 "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation");
  text = replace_all(text, "OFFSET 0 -10 0\n    CHANNELS", "OFFSET 0 0 0\n    CHANNELS");
  text = replace_all(text, "0 90 0 0 0 0 0 0 0", "0 90 0 0 0 0 0 -10 0 0 0 0");
  text = replace_all(text, "0 90 1 0 0 5 0 0 0", "0 90 1 0 0 5 0 -10 0 0 0 0");
  const auto file = parse_bvh(text, "t.bvh");
  ASSERT_TRUE(file.ok()) << file.message();
  EXPECT_EQ(file->channel_count, 12);
  EXPECT_EQ(file->joints[1].offset, glm::vec3(0.0f));
  EXPECT_EQ(file->joints[1].channels[4], BvhChannel::Xrotation);

  // A joint with CHANNELS 0 contributes no column.
  const std::string with_static = replace_all(kValid, "CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 0");
  const std::string motion_fixed = replace_all(replace_all(with_static, "0 90 0 0 0 0 0 0 0", "0 90 0 0 0 0"),
                                               "0 90 1 0 0 5 0 0 0", "0 90 1 0 0 5");
  const auto static_file = parse_bvh(motion_fixed, "t.bvh");
  ASSERT_TRUE(static_file.ok()) << static_file.message();
  EXPECT_EQ(static_file->channel_count, 6);
}

TEST(BvhParser, AcceptsBracesOnTheNameLineAndNamesWithSpaces) {
  std::string text = replace_all(kValid, "ROOT Hips\n{", "ROOT Hips {");
  text = replace_all(text, "JOINT Leg\n  {", "JOINT Left Leg\n  {");
  text = replace_all(text, "End Site\n    {", "End Site {");
  const auto file = parse_bvh(text, "t.bvh");
  ASSERT_TRUE(file.ok()) << file.message();
  EXPECT_EQ(file->joints[0].name, "Hips");
  EXPECT_EQ(file->joints[1].name, "Left Leg");
  EXPECT_TRUE(file->joints[1].has_end_site);
}

TEST(BvhParser, KeepsTheFirstOfSeveralEndSites) {
  const std::string text = replace_all(kValid, "      OFFSET 0 -10 0\n    }\n",
                                       "      OFFSET 0 -10 0\n    }\n    End Site\n    {\n      OFFSET 5 5 5\n    }\n");
  const auto file = parse_bvh(text, "t.bvh");
  ASSERT_TRUE(file.ok()) << file.message();
  EXPECT_EQ(file->joints[1].end_site_offset, glm::vec3(0.0f, -10.0f, 0.0f));
}

TEST(BvhParser, LenientFrameCountTakesTheLinesRead) {
  const std::string text = replace_all(kValid, "Frames: 2", "Frames: 1");
  EXPECT_FALSE(parse_bvh(text, "t.bvh").ok());
  const auto file = parse_bvh(text, "t.bvh", mmvk::BvhParseOptions{.strict_frame_count = false});
  ASSERT_TRUE(file.ok()) << file.message();
  EXPECT_EQ(file->frame_count, 2);
  EXPECT_EQ(file->values.size(), 18u);
  // Incomplete lines are still errors.
  const std::string short_line = replace_all(kValid, "0 90 1 0 0 5 0 0 0", "0 90 1");
  EXPECT_FALSE(parse_bvh(short_line, "t.bvh", mmvk::BvhParseOptions{.strict_frame_count = false}).ok());
}

TEST(BvhParser, DeepNestingDoesNotOverflowTheStack) {
  std::string text = "HIERARCHY\nROOT J0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
  const int depth = 5000;
  for (int i = 1; i < depth; ++i) text += "JOINT J" + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n";
  for (int i = 0; i < depth; ++i) text += "}\n";
  text += "MOTION\nFrames: 1\nFrame Time: 0.01\n";
  for (int i = 0; i < depth; ++i) text += "0 ";
  const auto file = parse_bvh(text, "deep.bvh");
  ASSERT_TRUE(file.ok()) << file.message();
  EXPECT_EQ(file->joints.size(), static_cast<std::size_t>(depth));
  EXPECT_EQ(file->joints.back().parent, depth - 2);
}

TEST(BvhParser, LoadBvhNamesAMissingFile) {
  const auto file = mmvk::load_bvh("/nonexistent/walk.bvh");
  ASSERT_FALSE(file.ok());
  EXPECT_NE(file.message().find("/nonexistent/walk.bvh"), std::string::npos) << file.message();
}

// --- The malformed corpus --------------------------------------------------

struct Expected {
  int line;
  std::string phrase;
};

// Each file in tests/corpus/bvh/ and the error it must produce. A new corpus
// file without an entry here fails CorpusIsFullyListed.
const std::map<std::string, Expected>& corpus_expectations() {
  static const std::map<std::string, Expected> kExpected{
      {"bad_channel_count.bvh", {9, "CHANNELS count must be an integer from 0 to 6"}},
      {"bad_end_site.bvh", {10, "expected 'End Site', got 'End' followed by 'Sight'"}},
      {"joint_without_name.bvh", {6, "JOINT without a name"}},
      {"unexpected_keyword.bvh", {9, "unexpected 'ROTATION' in JOINT Leg"}},
      {"binary_garbage.bvh", {1, "expected HIERARCHY"}},
      {"blank_only.bvh", {4, "file is empty"}},
      {"channel_count_mismatch.bvh", {9, "CHANNELS declares 3 channels but lists 2"}},
      {"duplicate_channel.bvh", {9, "'Zrotation' listed twice"}},
      {"empty.bvh", {1, "file is empty"}},
      {"end_site_with_channels.bvh", {12, "End Site has no CHANNELS"}},
      {"fewer_lines_than_frames.bvh", {21, "frame count mismatch: Frames: 3 but the file ends after 2 motion lines"}},
      {"fractional_frames.bvh", {17, "Frames: must be a non-negative integer, got '2.5'"}},
      {"huge_frame_claim.bvh", {21, "Frames: 2000000000 but the file ends after 2 motion lines"}},
      {"missing_close_brace.bvh", {15, "missing '}' to close ROOT Hips (opened at line 2) before MOTION"}},
      {"missing_frame_time.bvh", {18, "expected 'Frame Time:'"}},
      {"missing_frames.bvh", {17, "expected 'Frames:' after MOTION"}},
      {"missing_motion.bvh", {16, "missing MOTION section"}},
      {"missing_offset.bvh", {13, "JOINT Leg (opened at line 6) has no OFFSET"}},
      {"missing_open_brace.bvh", {7, "expected '{' after JOINT Leg, got 'OFFSET'"}},
      {"more_lines_than_frames.bvh", {20, "more motion lines than Frames: 1"}},
      {"nan_value.bvh", {19, "non-numeric token 'nan'"}},
      {"negative_frame_time.bvh", {18, "Frame Time: must be positive"}},
      {"negative_frames.bvh", {17, "Frames: must be a non-negative integer, got '-3'"}},
      {"no_channels.bvh", {13, "declares no CHANNELS"}},
      {"no_hierarchy_keyword.bvh", {1, "not a BVH file: expected HIERARCHY"}},
      {"non_numeric_value.bvh", {20, "non-numeric token 'zero'"}},
      {"second_root.bvh", {16, "second ROOT"}},
      {"short_offset.bvh", {8, "OFFSET of JOINT Leg needs 3 numbers; got 'CHANNELS' on line 9"}},
      {"too_few_values.bvh", {20, "too few values on motion line: 8, expected 9"}},
      {"too_many_values.bvh", {19, "too many values on motion line: 10, expected 9"}},
      {"truncated_hierarchy.bvh", {10, "unexpected end of file: missing '}' to close JOINT Leg"}},
      {"truncated_motion_crlf.bvh", {20, "too few values on motion line: 5, expected 9"}},
      {"unbalanced_close_brace.bvh", {16, "unbalanced '}'"}},
      {"unknown_channel.bvh", {9, "unknown channel 'Wrotation'"}},
      {"zero_frame_time.bvh", {18, "Frame Time: must be positive, got 0"}},
  };
  return kExpected;
}

std::filesystem::path corpus_dir() { return mmvk::test::test_source_dir() / "corpus" / "bvh"; }

TEST(BvhCorpus, CorpusIsFullyListed) {
  std::set<std::string> on_disk;
  for (const auto& entry : std::filesystem::directory_iterator(corpus_dir())) {
    on_disk.insert(entry.path().filename().string());
  }
  std::set<std::string> listed;
  for (const auto& [name, expected] : corpus_expectations()) listed.insert(name);
  EXPECT_EQ(on_disk, listed);
}

TEST(BvhCorpus, EachFileGetsItsError) {
  for (const auto& [name, expected] : corpus_expectations()) {
    const std::filesystem::path path = corpus_dir() / name;
    const auto file = mmvk::load_bvh(path);
    ASSERT_FALSE(file.ok()) << name << " parsed without error";
    const std::string prefix = path.string() + ":" + std::to_string(expected.line) + ": ";
    EXPECT_EQ(file.message().rfind(prefix, 0), 0u) << name << ": expected prefix '" << prefix << "', got: "
                                                    << file.message();
    EXPECT_NE(file.message().find(expected.phrase), std::string::npos)
        << name << ": expected '" << expected.phrase << "' in: " << file.message();
  }
}

// --- Garbage ---------------------------------------------------------------

// Every message starts with "source:line: ".
void expect_located_error(const mmvk::Result<mmvk::BvhFile>& file, const std::string& what) {
  if (file.ok()) return;
  const std::string& message = file.message();
  ASSERT_EQ(message.rfind("g.bvh:", 0), 0u) << what << ": " << message;
  const std::size_t colon = message.find(':', 6);
  ASSERT_NE(colon, std::string::npos) << what << ": " << message;
  const std::string line = message.substr(6, colon - 6);
  ASSERT_FALSE(line.empty()) << what << ": " << message;
  EXPECT_TRUE(std::all_of(line.begin(), line.end(), [](char c) { return c >= '0' && c <= '9'; }))
      << what << ": " << message;
}

TEST(BvhGarbage, EveryTruncationFailsCleanly) {
  for (std::size_t size = 0; size < kValid.size(); ++size) {
    const auto file = parse_bvh(std::string_view(kValid).substr(0, size), "g.bvh");
    expect_located_error(file, "prefix of " + std::to_string(size) + " bytes");
    // Only a cut inside the last line's trailing newline can still be valid.
    if (size + 1 < kValid.size()) {
      EXPECT_FALSE(file.ok()) << "prefix of " << size << " bytes parsed";
    }
  }
}

TEST(BvhGarbage, RandomByteChangesNeverCrash) {
  std::mt19937 rng(1234);
  const std::string alphabet = "{}0123456789.-+eE \t\r\nXYZ:HIERARCHYROOTJOINTEndSiteOFFSETCHANNELSMOTIONFrames";
  for (int trial = 0; trial < 3000; ++trial) {
    std::string text = kValid;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % text.size();
      switch (rng() % 3) {
        case 0: text[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: text.erase(at, 1 + rng() % 8); break;
        default: text.insert(at, 1, static_cast<char>(rng() % 256)); break;
      }
    }
    const auto file = parse_bvh(text, "g.bvh");
    expect_located_error(file, "trial " + std::to_string(trial));
    if (file.ok()) {
      // Whatever parsed is self-consistent.
      EXPECT_EQ(file->values.size(),
                static_cast<std::size_t>(file->frame_count) * static_cast<std::size_t>(file->channel_count));
      EXPECT_GT(file->frame_time, 0.0);
    }
  }
}

TEST(BvhGarbage, HugeFrameClaimDoesNotAllocate) {
  // Would need 2e9 x 9 floats (72 GB) if reserved from the header.
  const std::string text = replace_all(kValid, "Frames: 2", "Frames: 2000000000");
  const auto file = parse_bvh(text, "g.bvh");
  ASSERT_FALSE(file.ok());
  EXPECT_NE(file.message().find("frame count mismatch"), std::string::npos) << file.message();
  const auto too_big = parse_bvh(replace_all(kValid, "Frames: 2", "Frames: 99999999999"), "g.bvh");
  ASSERT_FALSE(too_big.ok());
  EXPECT_NE(too_big.message().find("too large"), std::string::npos) << too_big.message();
}

}  // namespace
