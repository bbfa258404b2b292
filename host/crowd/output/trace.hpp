// `mmvk crowd --trace FILE --trace-agents M`: the displayed world joint
// positions of the first M characters after every tick, for anyone to
// measure the motion with their own tools.
//
// FILE: raw float32, little-endian, [ticks x M x joints x 3] (x, y, z),
// metres, world space, Y up; row t is the pose shown after tick t, at time
// (t + 1) / tick_rate_hz seconds. No header: the shape is in the sidecar.
// FILE.json, the sidecar: format, version, positions_file, dtype,
// byte_order, shape, tick_rate_hz, ticks, agents, joints, joint_names (any
// invalid UTF-8 replaced), parents (-1 for a root), contact_joints (left,
// right; -1 when none), contacts ([ticks][M] FootContact bits of the played
// frame, contact_bits names them), foot_locks ([ticks][M], bit 0: left foot
// locked, bit 1: right).
//
// The trace is held in memory during the run and written when it ends, each
// file atomically (a temp file renamed over the target), so its size is
// capped at kMaxTraceBytes; every check (agents, size, writable paths) runs
// before the simulation starts.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

// The largest positions file --trace writes, and so the memory it holds:
// 512 MiB (10 characters of 60 joints for 10 minutes at 60 Hz take 247 MiB).
inline constexpr std::uint64_t kMaxTraceBytes = std::uint64_t{512} << 20;

std::filesystem::path trace_sidecar_path(const std::filesystem::path& trace);

struct TraceLayout {
  std::uint64_t ticks = 0;
  std::uint32_t agents = 0;  // traced, the first of the crowd
  std::uint32_t joints = 0;
  double tick_rate_hz = 0.0;

  std::uint64_t position_bytes() const { return ticks * agents * joints * 12; }
};

class TraceWriter {
 public:
  // Checks everything a run could otherwise fail on at its end; errors name
  // --trace or --trace-agents: agents beyond the crowd's `crowd_agents`, a
  // trace over kMaxTraceBytes, FILE or FILE.json not writable (check_writable).
  static Result<TraceWriter> create(const std::filesystem::path& path, const TraceLayout& layout,
                                    const Skeleton& skeleton, std::array<int, 2> contact_joints,
                                    std::uint32_t crowd_agents);

  // After each tick: world [crowd x joints] (the displayed pose), contacts
  // [crowd] FootContact bits, locked [crowd x 2] (left, right; may be
  // empty: none locked). Extra ticks beyond the layout's are ignored.
  void record(std::span<const glm::vec3> world, std::span<const std::uint8_t> contacts,
              std::span<const std::uint8_t> locked);

  // Writes FILE, then FILE.json. Errors name the file.
  Status finish() const;
  std::uint64_t ticks_recorded() const { return recorded_; }

 private:
  TraceWriter() = default;

  std::filesystem::path path_;
  TraceLayout layout_;
  std::vector<std::string> names_;
  std::vector<int> parents_;
  std::array<int, 2> contact_joints_{-1, -1};
  std::string positions_;               // the file's bytes, reserved once
  std::vector<std::uint8_t> contacts_;  // [ticks x agents]
  std::vector<std::uint8_t> locks_;     // [ticks x agents]
  std::uint64_t recorded_ = 0;
};

// A trace read back (tools and tests): the sidecar's layout and arrays, and
// the positions [ticks x agents x joints x 3].
struct Trace {
  TraceLayout layout;
  std::vector<std::string> joint_names;
  std::vector<int> parents;
  std::array<int, 2> contact_joints{-1, -1};
  std::vector<float> positions;
  std::vector<std::uint8_t> contacts;   // [ticks x agents]
  std::vector<std::uint8_t> foot_locks;  // [ticks x agents]
};

// Errors name the file and the field: a sidecar that is not a trace's, a
// positions file whose size does not match its shape.
Result<Trace> read_trace(const std::filesystem::path& path);

}  // namespace mmvk::crowd
