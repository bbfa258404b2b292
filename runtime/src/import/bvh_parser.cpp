// BVH text -> BvhFile. Hierarchy keywords are matched case-insensitively,
// tokens may be separated by any blanks, and CR/LF/CRLF all end a line. The
// motion section is read line by line: every non-empty line is one frame and
// must hold exactly `channel_count` numbers, and the number of such lines must
// equal "Frames:". Every error names the file and the 1-based line.
#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "import/bvh_lexer.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/input_text.hpp"
#include "mmvk/import/bvh.hpp"

namespace mmvk {

namespace {

using detail::BvhCursor;

// Guards against garbage that would otherwise allocate without bound; real
// skeletons have tens to a few hundred joints.
constexpr std::size_t kMaxJoints = 10000;

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i];
    char y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

bool istarts_with(std::string_view text, std::string_view prefix) {
  return text.size() >= prefix.size() && iequals(text.substr(0, prefix.size()), prefix);
}

std::optional<BvhChannel> channel_from_name(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, BvhChannel>, 6> kNames{{
      {"Xposition", BvhChannel::Xposition},
      {"Yposition", BvhChannel::Yposition},
      {"Zposition", BvhChannel::Zposition},
      {"Xrotation", BvhChannel::Xrotation},
      {"Yrotation", BvhChannel::Yrotation},
      {"Zrotation", BvhChannel::Zrotation},
  }};
  for (const auto& [text, channel] : kNames) {
    if (iequals(name, text)) return channel;
  }
  return std::nullopt;
}

// A short, printable excerpt of a token for error messages (garbage input can
// hold control bytes or megabytes without a space): the rule of every
// message that echoes input (mmvk/common/input_text.hpp).
std::string quote(std::string_view token) {
  std::string out = "'";
  out += printable_text(token, 40);
  out += '\'';
  return out;
}

template <class Int>
std::optional<Int> parse_integer(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  Int value{};
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (token.empty() || error != std::errc{} || end != token.data() + token.size()) return std::nullopt;
  return value;
}

class Parser {
 public:
  Parser(std::string_view text, std::string_view source, const BvhParseOptions& options)
      : cursor_(text), options_(options) {
    file_.source = std::string(source);
  }

  Result<BvhFile> run() {
    MMVK_TRY(parse_hierarchy());
    MMVK_TRY(parse_motion_header());
    MMVK_TRY(parse_frames());
    return std::move(file_);
  }

 private:
  Error fail(int line, const std::string& message) const {
    return make_error(file_.source + ":" + std::to_string(line) + ": " + message);
  }

  std::string describe(int joint) const {
    return (joint == 0 ? "ROOT " : "JOINT ") + file_.joints[static_cast<std::size_t>(joint)].name;
  }

  // After ROOT/JOINT/End Site: the name was already consumed; expects '{'.
  Status expect_open_brace(bool brace_on_name_line, const std::string& what) {
    if (brace_on_name_line) return {};
    int line = 0;
    const std::string_view token = cursor_.next_token(&line);
    if (token != "{") {
      return fail(line, "expected '{' after " + what + ", got " + (token.empty() ? "end of file" : quote(token)));
    }
    return {};
  }

  // Reads "NAME" or "NAME {" from the rest of the line.
  Result<std::pair<std::string, bool>> read_name(int line, std::string_view keyword) {
    std::string_view name = cursor_.rest_of_line();
    bool brace = false;
    if (!name.empty() && name.back() == '{') {
      brace = true;
      name.remove_suffix(1);
      while (!name.empty() && detail::is_blank(name.back())) name.remove_suffix(1);
    }
    if (name.empty()) return fail(line, std::string(keyword) + " without a name");
    return std::pair<std::string, bool>{std::string(name), brace};
  }

  Status read_offset(int line, glm::vec3& out, const std::string& owner) {
    for (int axis = 0; axis < 3; ++axis) {
      int token_line = 0;
      const std::string_view token = cursor_.next_token(&token_line);
      const std::optional<float> value = detail::parse_float(token);
      if (!value) {
        return fail(line, "OFFSET of " + owner + " needs 3 numbers; got " +
                              (token.empty() ? std::string("end of file") : quote(token)) +
                              (token_line != line ? " on line " + std::to_string(token_line) : std::string()));
      }
      out[axis] = *value;
    }
    return {};
  }

  Status read_channels(int line, BvhJoint& joint, const std::string& owner) {
    if (!joint.channels.empty()) return fail(line, "second CHANNELS line in " + owner);
    const std::string_view count_token = cursor_.next_token_on_line();
    const std::optional<int> count = parse_integer<int>(count_token);
    if (!count || *count < 0 || *count > 6) {
      return fail(line, "CHANNELS count must be an integer from 0 to 6, got " +
                            (count_token.empty() ? std::string("nothing") : quote(count_token)) + " in " + owner);
    }
    std::vector<BvhChannel> channels;
    for (;;) {
      const std::string_view name = cursor_.next_token_on_line();
      if (name.empty()) break;
      const std::optional<BvhChannel> channel = channel_from_name(name);
      if (!channel) return fail(line, "unknown channel " + quote(name) + " in " + owner);
      if (std::find(channels.begin(), channels.end(), *channel) != channels.end()) {
        return fail(line, "channel " + quote(name) + " listed twice in " + owner);
      }
      channels.push_back(*channel);
      if (channels.size() > 6) break;
    }
    if (static_cast<int>(channels.size()) != *count) {
      return fail(line, "CHANNELS declares " + std::to_string(*count) + " channels but lists " +
                            std::to_string(channels.size()) + " in " + owner);
    }
    joint.channels = std::move(channels);
    return {};
  }

  // Open blocks while the hierarchy is read: a joint, or an End Site of that joint.
  struct Block {
    int joint;
    bool end_site;
    int open_line;
    bool has_offset;
    bool keep_end_site;
  };

  Status parse_hierarchy() {
    int line = 0;
    MMVK_TRY(parse_root(line));
    std::vector<Block> open{{0, false, line, false, false}};
    while (!open.empty()) {
      const std::string owner =
          open.back().end_site ? "End Site of " + describe(open.back().joint) : describe(open.back().joint);
      const std::string_view token = cursor_.next_token(&line);
      if (token.empty()) {
        return fail(line, "unexpected end of file: missing '}' to close " + owner + " (opened at line " +
                              std::to_string(open.back().open_line) + ")");
      }
      MMVK_TRY(parse_block_token(open, token, line, owner));
    }
    return number_channels(line);
  }

  // "HIERARCHY", then "ROOT name {".
  Status parse_root(int& line) {
    std::string_view token = cursor_.next_token(&line);
    if (token.empty()) return fail(line, "file is empty (expected HIERARCHY)");
    // Nothing of a file is echoed before it is known to be BVH: a manifest
    // may name any file the user can read (/etc/shadow, run as root).
    if (!iequals(token, "HIERARCHY")) {
      return fail(line, "not a BVH file: expected HIERARCHY at its start (its content is not shown)");
    }
    token = cursor_.next_token(&line);
    if (!iequals(token, "ROOT")) {
      return fail(line, "expected ROOT after HIERARCHY, got " + (token.empty() ? "end of file" : quote(token)));
    }
    auto root_name = read_name(line, "ROOT");
    if (!root_name) return root_name.status();
    file_.joints.emplace_back();
    file_.joints.back().name = root_name->first;
    return expect_open_brace(root_name->second, "ROOT " + root_name->first);
  }

  // One token inside the innermost open block (`owner` names it).
  Status parse_block_token(std::vector<Block>& open, std::string_view token, int line, const std::string& owner) {
    Block& block = open.back();
    BvhJoint& joint = file_.joints[static_cast<std::size_t>(block.joint)];
    if (iequals(token, "OFFSET")) {
      if (block.has_offset) return fail(line, "second OFFSET in " + owner);
      glm::vec3 ignored{0.0f};
      glm::vec3& target = !block.end_site ? joint.offset : block.keep_end_site ? joint.end_site_offset : ignored;
      MMVK_TRY(read_offset(line, target, owner));
      block.has_offset = true;
    } else if (iequals(token, "CHANNELS")) {
      if (block.end_site) return fail(line, "an End Site has no CHANNELS (" + owner + ")");
      MMVK_TRY(read_channels(line, joint, owner));
    } else if (iequals(token, "JOINT")) {
      MMVK_TRY(open_joint(open, line, owner));
    } else if (iequals(token, "End")) {
      MMVK_TRY(open_end_site(open, line, owner));
    } else if (token == "}") {
      if (!block.has_offset) {
        return fail(line, owner + " (opened at line " + std::to_string(block.open_line) + ") has no OFFSET");
      }
      open.pop_back();
    } else if (iequals(token, "MOTION")) {
      return fail(line, "missing '}' to close " + owner + " (opened at line " + std::to_string(block.open_line) +
                            ") before MOTION");
    } else {
      return fail(line, "unexpected " + quote(token) + " in " + owner);
    }
    return {};
  }

  // "JOINT name {" inside a joint: the child joint's block opens.
  Status open_joint(std::vector<Block>& open, int line, const std::string& owner) {
    const Block& block = open.back();
    if (block.end_site) return fail(line, "JOINT inside an End Site (" + owner + ")");
    if (!block.has_offset) return fail(line, owner + " has no OFFSET before its first child");
    if (file_.joints.size() >= kMaxJoints) return fail(line, "more than " + std::to_string(kMaxJoints) + " joints");
    auto name = read_name(line, "JOINT");
    if (!name) return name.status();
    const int parent = block.joint;
    file_.joints.emplace_back();
    file_.joints.back().name = name->first;
    file_.joints.back().parent = parent;
    MMVK_TRY(expect_open_brace(name->second, "JOINT " + name->first));
    open.push_back({static_cast<int>(file_.joints.size()) - 1, false, line, false, false});
    return {};
  }

  // "End Site {" inside a joint.
  Status open_end_site(std::vector<Block>& open, int line, const std::string& owner) {
    const Block& block = open.back();
    if (block.end_site) return fail(line, "End Site inside an End Site (" + owner + ")");
    const std::string_view site = cursor_.next_token_on_line();
    bool brace = false;
    if (iequals(site, "Site{")) {
      brace = true;
    } else if (!iequals(site, "Site")) {
      return fail(line, "expected 'End Site', got 'End' followed by " + (site.empty() ? "nothing" : quote(site)));
    }
    // A second End Site (some exporters write one per tip) is parsed and
    // checked but not kept: BvhJoint holds one.
    BvhJoint& joint = file_.joints[static_cast<std::size_t>(block.joint)];
    const bool keep = !joint.has_end_site;
    joint.has_end_site = true;
    const int owner_joint = block.joint;
    MMVK_TRY(expect_open_brace(brace, "End Site of " + describe(owner_joint)));
    open.push_back({owner_joint, true, line, false, keep});
    return {};
  }

  // Each joint's first channel in a frame's values, and their count.
  Status number_channels(int line) {
    int channel_count = 0;
    for (BvhJoint& joint : file_.joints) {
      joint.first_channel = channel_count;
      channel_count += static_cast<int>(joint.channels.size());
    }
    file_.channel_count = channel_count;
    if (channel_count == 0) return fail(line, "the hierarchy declares no CHANNELS");
    return {};
  }

  Status parse_motion_header() {
    int line = 0;
    std::string_view token = cursor_.next_token(&line);
    if (token.empty()) return fail(line, "missing MOTION section after the hierarchy");
    if (iequals(token, "ROOT")) return fail(line, "a second ROOT hierarchy is not supported");
    if (token == "}") return fail(line, "unbalanced '}' after the hierarchy's last block");
    if (!iequals(token, "MOTION")) return fail(line, "expected MOTION after the hierarchy, got " + quote(token));

    // "Frames:", "Frames :", "Frames:\t344" or "Frames:344".
    token = cursor_.next_token(&line);
    if (!istarts_with(token, "Frames")) {
      return fail(line, "expected 'Frames:' after MOTION, got " + (token.empty() ? "end of file" : quote(token)));
    }
    std::string_view value = token.substr(6);
    if (value.empty()) value = cursor_.next_token_on_line();
    if (!value.empty() && value.front() == ':') value.remove_prefix(1);
    else return fail(line, "expected ':' after Frames");
    if (value.empty()) value = cursor_.next_token_on_line();
    const std::optional<std::int64_t> frames = parse_integer<std::int64_t>(value);
    if (!frames || *frames < 0) {
      return fail(line, "Frames: must be a non-negative integer, got " +
                            (value.empty() ? std::string("nothing") : quote(value)));
    }
    if (*frames > std::numeric_limits<std::int32_t>::max()) {
      return fail(line, "Frames: " + std::string(value) + " is too large");
    }
    file_.frame_count = static_cast<int>(*frames);
    if (!cursor_.finish_line()) return fail(line, "unexpected text after Frames:");

    // "Frame Time: 0.0083", "Frame Time:\t.0083333", "Frame Time : ...".
    token = cursor_.next_token(&line);
    if (!iequals(token, "Frame")) {
      return fail(line, "expected 'Frame Time:' after Frames:, got " + (token.empty() ? "end of file" : quote(token)));
    }
    token = cursor_.next_token_on_line();
    if (!istarts_with(token, "Time")) return fail(line, "expected 'Frame Time:'");
    value = token.substr(4);
    if (value.empty()) value = cursor_.next_token_on_line();
    if (!value.empty() && value.front() == ':') value.remove_prefix(1);
    else return fail(line, "expected ':' after Frame Time");
    if (value.empty()) value = cursor_.next_token_on_line();
    const std::optional<double> frame_time = detail::parse_double(value);
    if (!frame_time) {
      return fail(line, "Frame Time: must be a number, got " + (value.empty() ? std::string("nothing") : quote(value)));
    }
    if (!(*frame_time > 0.0)) {
      return fail(line, "Frame Time: must be positive, got " + std::string(value));
    }
    file_.frame_time = *frame_time;
    if (!cursor_.finish_line()) return fail(line, "unexpected text after Frame Time:");
    return {};
  }

  Status parse_frames() {
    const std::size_t channels = static_cast<std::size_t>(file_.channel_count);
    const std::size_t claimed = static_cast<std::size_t>(file_.frame_count);
    // Reserve no more than the remaining text could hold (a value takes at
    // least 2 bytes), so a bogus "Frames: 2000000000" cannot allocate gigabytes.
    const std::size_t possible = cursor_.remaining_bytes() / (2 * channels) + 1;
    file_.values.reserve(std::min(claimed, possible) * channels);
    // One spare slot per line lets read_number_line count extra values.
    std::vector<float> line_values(channels);
    for (std::size_t frame = 0;; ++frame) {
      if (!cursor_.skip_empty_lines()) {
        if (!options_.strict_frame_count) {
          file_.frame_count = static_cast<int>(frame);
          return {};
        }
        if (frame < claimed) {
          return fail(cursor_.line(), "frame count mismatch: Frames: " + std::to_string(claimed) +
                                          " but the file ends after " + std::to_string(frame) + " motion lines");
        }
        return {};
      }
      const int line = cursor_.line();
      if (frame >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
        return fail(line, "more than 2^31 - 1 motion lines");
      }
      if (frame == claimed && options_.strict_frame_count) {
        return fail(line, "frame count mismatch: more motion lines than Frames: " + std::to_string(claimed));
      }
      std::string_view bad_token;
      const int count = cursor_.read_number_line(line_values.data(), file_.channel_count, &bad_token);
      if (count < 0) {
        return fail(line, "non-numeric token " + quote(bad_token) + " in motion line (frame " +
                              std::to_string(frame) + ")");
      }
      if (static_cast<std::size_t>(count) != channels) {
        return fail(line, std::string(static_cast<std::size_t>(count) < channels ? "too few" : "too many") +
                              " values on motion line: " + std::to_string(count) + ", expected " +
                              std::to_string(channels) + " (frame " + std::to_string(frame) + ")");
      }
      file_.values.insert(file_.values.end(), line_values.begin(), line_values.end());
    }
  }

  BvhCursor cursor_;
  BvhParseOptions options_;
  BvhFile file_;
};

}  // namespace

Result<BvhFile> parse_bvh(std::string_view text, std::string_view source, const BvhParseOptions& options) {
  return Parser(text, source, options).run();
}

Result<BvhFile> parse_bvh(std::string_view text, std::string_view source) {
  return parse_bvh(text, source, BvhParseOptions{});
}

Result<BvhFile> load_bvh(const std::filesystem::path& path, const BvhParseOptions& options) {
  Result<std::string> text = read_file(path);
  if (!text) return text.error();
  return parse_bvh(*text, path.string(), options);
}

Result<BvhFile> load_bvh(const std::filesystem::path& path) { return load_bvh(path, BvhParseOptions{}); }

}  // namespace mmvk
