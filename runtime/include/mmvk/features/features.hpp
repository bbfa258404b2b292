// Raw feature extraction: one clip of motion + its character root + the
// feature schema -> a [frames x schema.dims()] matrix of raw (unnormalized)
// features in character space.
//
// Character space of frame f: origin at the character root position (on the
// ground), +Z along the root's facing, +Y up, +X to the character's left
// (right-handed). Every channel kind is expressed in it (each kind's entry in
// channel_kinds.hpp says what it reads; the built-in kinds):
//   - BonePosition: global bone position minus the root position, rotated
//     into character space, metres.
//   - BoneVelocity / RootVelocity: the global bone velocity rotated into
//     character space, m/s. Velocities are finite differences of global
//     positions: central inside the clip, one-sided on its first and last
//     frame (0 for a one-frame clip). RootVelocity uses the channel's `bone`,
//     or "@hips" when it is empty.
//   - TrajectoryPosition: the root position `k` frames ahead, (x, z) in the
//     current character space, metres; k = round(offset_seconds * fps), at
//     least 1 in magnitude; a negative offset looks `|k|` frames back (the
//     past trajectory).
//   - TrajectoryDirection: the root facing `k` frames ahead (or back), (x, z)
//     in the current character space (a unit vector).
//   - Custom: values copied from the caller's per-channel arrays.
//   - RootAngularVelocity: the signed angle between the root facings of the
//     neighbouring frames over their time (central inside the clip,
//     one-sided on its first and last frame), rad/s, positive = turning
//     left (from +Z towards +X).
//   - FootContact: 1 while the foot is planted, else 0, (left, right), by
//     the detection of foot_contacts.hpp with options.contacts (the same
//     parameters the build gives the animation section).
//   - LimbVector: (second_bone - bone) in character space divided by the sum
//     of the segment lengths on the chain from bone down to second_bone, on
//     the same frame; unitless, |v| <= 1 (1 = the limb fully stretched).
//   - Phase (phase_features.cpp): per source curve, the dominant frequency of
//     the curve over a centred window of +-window_seconds with its mean
//     removed, its amplitude a and its phase phi (cycles, at the window's
//     centre): (a sin 2 pi phi, a cos 2 pi phi) in the curve's units. A
//     curve is "<bone>.speed" (|velocity|, m/s), "<bone>.height" (global y,
//     m) or the dimension name of an earlier channel ("left_foot_velocity.y",
//     its raw value).
//
// Frames past the start or end of a clip (trajectory offsets, phase windows):
// a looping clip wraps (its last frame is followed by its first, displaced by
// one "cycle": the rigid ground motion from frame 0 to the frame after the
// last, extrapolated from the last step; and the other way round before its
// first frame); a non-looping clip clamps to its first or last frame and
// reports the frame as running past an edge (the database build turns that
// into kFrameEdgeExcluded or ignores it, depending on its edge rule).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mmvk/import/character.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/features/foot_contacts.hpp"
#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

struct FeatureExtractionOptions {
  bool loop = false;
  // Names the clip in error messages (usually the BVH path).
  std::string source;
  // One array per Custom channel, in schema order, each [frame_count x
  // custom_dims]. Must hold exactly as many arrays as the schema has Custom
  // channels.
  std::span<const std::vector<float>> custom;
  // Foot contact detection for FootContact channels.
  FootContactParams contacts;
  // > 0: a non-looping clip's trajectory offsets that reach past its last
  // (or before its first) frame are extrapolated at the constant speed and
  // turning rate of its last (first) this many seconds, instead of clamped,
  // and do not count as running past the edge (past_end); phase windows
  // still clamp and count. 0: clamp (the edge rule's default).
  float extrapolate_seconds = 0.0f;
};

struct RawFeatures {
  std::uint32_t frame_count = 0;
  std::uint32_t dims = 0;
  std::vector<float> values;            // [frame_count x dims], row-major, raw units
  // [frame_count]: 1 when a trajectory offset or phase window ran past a
  // non-looping clip's start or end and was clamped (the name is older than
  // the past trajectory; extrapolated offsets do not count)
  std::vector<std::uint8_t> past_end;
};

// Frames ahead for a trajectory offset at `fps`: round(seconds * fps), >= 1.
std::uint32_t offset_frames(float offset_seconds, float fps);

// Frames from now for a trajectory offset of either sign: offset_frames() of
// its magnitude, negative for a negative offset.
std::int64_t signed_offset_frames(float offset_seconds, float fps);

// Largest future trajectory offset of the schema in frames at `fps` (0 when
// the schema has no trajectory channel).
std::uint32_t max_offset_frames(const FeatureSchema& schema, float fps);

// How far the schema's channels read before and after the current frame, in
// frames at `fps`: past trajectory offsets and phase windows reach back,
// future offsets and phase windows ahead. A non-looping clip's frame f runs
// past an edge when f < before or f + after > last frame.
// With `trajectory` false, only the phase windows count (the reach that
// still clamps when trajectories are extrapolated).
struct EdgeReach {
  std::uint32_t before = 0;
  std::uint32_t after = 0;
};
EdgeReach edge_reach(const FeatureSchema& schema, float fps, bool trajectory = true);

// Half-width of a phase window in frames: round(window_seconds * fps), >= 1.
std::uint32_t window_frames(float window_seconds, float fps);

// Extracts raw features. Bones are resolved with find_bone() on the motion's
// skeleton; an unresolved bone is an error naming the channel and the source.
// Further errors, naming the source, the channel and the field: a phase
// window longer than the clip (2 x window + 1 frames > frames); on a
// non-looping clip with past trajectory offsets, a reach before and after
// that leaves no frame inside the edges; an unknown curve; a LimbVector whose
// second_bone does not hang below its bone; for FootContact, a foot whose toe
// and heel both fail to resolve.
// Preconditions: root arrays sized motion.frame_count.
Result<RawFeatures> extract_features(const Motion& motion, const CharacterRoot& root, const FeatureSchema& schema,
                                     const FeatureExtractionOptions& options);

// Custom channel sidecars: the values of Custom channel `name` for clip
// `dir/walk.bvh` are read from `dir/walk.name.f32`, raw little-endian float32
// [source frames x custom_dims] at the BVH's own frame rate (before any
// resampling). Returns the path for a clip file.
std::filesystem::path custom_sidecar_path(const std::filesystem::path& bvh_path, const FeatureChannel& channel);

// Loads a sidecar and checks its size against `frame_count` x channel dims.
Result<std::vector<float>> load_custom_sidecar(const std::filesystem::path& bvh_path, const FeatureChannel& channel,
                                               std::uint32_t frame_count);

// Linear resampling of per-frame values [src_frames x dims] at src_fps to
// dst_frames at dst_fps (times clamped to the source's last frame).
std::vector<float> resample_values(std::span<const float> values, std::uint32_t dims, std::uint32_t src_frames,
                                   float src_fps, std::uint32_t dst_frames, float dst_fps);

}  // namespace mmvk
