#include "mmvk/database/database_build.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/import/import_check.hpp"
#include "mmvk/features/normalization.hpp"
#include "mmvk/import/scene_import.hpp"
#include "database/animation_build.hpp"
#include "database/cost_overflow.hpp"

namespace mmvk {

namespace {

// One database clip after feature extraction, before normalization.
struct ProcessedClip {
  Clip clip;                        // first_frame and tags filled in at assembly
  std::vector<std::string> tags;
  RawFeatures raw;
  std::vector<std::uint32_t> flags;  // [frames]
  float fps = 0.0f;
  detail::ClipAnimation animation;   // empty when the build stores no animation
  std::vector<TagRange> tag_ranges;  // numbered into masks at assembly
  // [frames] each when the clip has cost ranges, else empty (the clip's values).
  std::vector<float> multiplier;
  std::vector<float> bias;
  std::vector<GaitTags> gait;  // [frames] when gait bands are measured
};

bool in_range(std::size_t frame, float fps, const TimeRange& range) {
  const double t = static_cast<double>(frame) / fps;
  return t >= range.begin_seconds && t < range.end_seconds;
}

void flag_ranges(std::span<const TimeRange> ranges, float fps, std::uint32_t flag, std::vector<std::uint32_t>& flags) {
  for (const TimeRange& range : ranges) {
    for (std::size_t f = 0; f < flags.size(); ++f) {
      if (in_range(f, fps, range)) flags[f] |= flag;
    }
  }
}

// A tag or cost range must cover at least one frame and end at most one frame
// past the clip (a range written up to the clip's length in seconds is fine).
Status check_inside(const TimeRange& range, std::uint32_t frames, float fps, const std::string& field) {
  const double duration = double(frames) / fps;
  std::uint32_t covered = 0;
  for (std::uint32_t f = 0; f < frames; ++f) covered += in_range(f, fps, range) ? 1u : 0u;
  if (covered > 0 && double(range.end_seconds) <= duration + 1.0 / fps) return {};
  char text[200];
  std::snprintf(text, sizeof(text), ": [%g, %g) s lies %s the clip (%u frames, %.4g s at %g fps)",
                double(range.begin_seconds), double(range.end_seconds), covered == 0 ? "outside" : "partly outside",
                frames, duration, double(fps));
  return make_error(field + text);
}

// Checks that the clip's tag and cost ranges lie inside it, keeps its tag
// ranges for assembly, and computes per-frame multipliers and biases.
Status apply_time_ranges(const ManifestClip& meta, std::uint32_t frames, float fps, ProcessedClip& out) {
  const std::string field = meta.field.empty() ? meta.file.string() + ": clip '" + meta.name + "'" : meta.field;
  for (std::size_t i = 0; i < meta.tag_ranges.size(); ++i) {
    const TagRange& tag = meta.tag_ranges[i];
    std::size_t index = 0;
    for (std::size_t j = 0; j < i; ++j) index += meta.tag_ranges[j].tag == tag.tag ? 1 : 0;
    MMVK_TRY(check_inside(tag.range, frames, fps,
                          field + ".tag_ranges." + tag.tag + "[" + std::to_string(index) + "]"));
  }
  out.tag_ranges = meta.tag_ranges;
  if (meta.cost_ranges.empty()) return {};
  out.multiplier.assign(frames, meta.cost_multiplier);
  out.bias.assign(frames, meta.cost_bias);
  for (std::size_t i = 0; i < meta.cost_ranges.size(); ++i) {
    const CostRange& cost = meta.cost_ranges[i];
    MMVK_TRY(check_inside(cost.range, frames, fps, field + ".cost_ranges[" + std::to_string(i) + "].range"));
    for (std::uint32_t f = 0; f < frames; ++f) {
      if (!in_range(f, fps, cost.range)) continue;
      out.multiplier[f] *= cost.cost_multiplier;
      out.bias[f] += cost.cost_bias;
    }
  }
  for (std::uint32_t f = 0; f < frames; ++f) {
    if (!(out.multiplier[f] > 0.0f) || !std::isfinite(out.multiplier[f]) || !std::isfinite(out.bias[f])) {
      return make_error(field + ".cost_ranges: frame " + std::to_string(f) +
                        "'s product of multipliers or sum of biases is not finite and positive");
    }
  }
  return {};
}

// The index of `tag` in `names`, adding it; errors past kMaxTags.
Result<std::size_t> tag_index(std::vector<std::string>& names, const std::string& tag, const std::string& source,
                              const std::string& clip) {
  auto it = std::find(names.begin(), names.end(), tag);
  if (it != names.end()) return static_cast<std::size_t>(it - names.begin());
  if (tag.starts_with(kGaitTagPrefix)) {
    return make_error(source + ": clip '" + clip + "': tag '" + tag + "' begins with '" + std::string(kGaitTagPrefix) +
                      "', which is kept for the measured gait tags (gait_bands.hpp)");
  }
  if (names.size() == kMaxTags) {
    return make_error(source + ": more than " + std::to_string(kMaxTags) + " distinct tags (clip '" + clip +
                      "' adds '" + tag + "')");
  }
  names.push_back(tag);
  return names.size() - 1;
}

// The plausibility rule of database_build.hpp, on one clip's raw features.
Status check_plausible(const RawFeatures& raw, const FeatureSchema& schema, float fps, const std::string& source) {
  std::uint32_t first = 0;
  for (const FeatureChannel& channel : schema.channels) {
    const std::uint32_t dims = channel.dims();
    const ChannelKindInfo& kind = channel_kind_info(channel.kind);
    for (std::uint32_t f = 0; kind.plausible_limit > 0.0f && f < raw.frame_count; ++f) {
      for (std::uint32_t d = first; d < first + dims; ++d) {
        const float value = raw.values[std::size_t{f} * raw.dims + d];
        if (std::abs(value) <= kind.plausible_limit) continue;
        char text[320];
        std::snprintf(text, sizeof(text), "frame %u (%.3f s), channel '%s': %g %s is beyond the limit of %g %s", f,
                      double(f) / fps, channel.name.c_str(), double(value), kind.limit_unit.data(),
                      double(kind.plausible_limit), kind.limit_unit.data());
        return make_error(source + ": " + text +
                          " (physically impossible motion: a corrupt value or wrong units in the file?)");
      }
    }
    first += dims;
  }
  return {};
}

Result<ProcessedClip> process_motion(const ManifestClip& meta, const Motion& motion,
                                     std::span<const std::vector<float>> custom, bool mirrored,
                                     const MotionBuildSettings& settings) {
  const std::string source = meta.file.string() + (mirrored ? " (mirrored)" : "");
  if (motion.frame_count == 0) return make_error(source + ": the clip has no frames");
  Result<CharacterRoot> root = compute_character_root(motion, settings.character_root);
  if (!root.ok()) return make_error(source + ": " + root.message());
  FeatureExtractionOptions options;
  options.loop = meta.loop;
  options.source = source;
  options.custom = custom;
  options.contacts = settings.contacts;  // foot_contact channels agree with the animation's contacts
  if (settings.edge_rule == EdgeRule::Extrapolate) options.extrapolate_seconds = kExtrapolateSeconds;
  Result<RawFeatures> raw = extract_features(motion, *root, settings.schema, options);
  if (!raw.ok()) return raw.error();
  MMVK_TRY(check_plausible(*raw, settings.schema, motion.fps, source + ": clip '" + meta.name + "'"));

  ProcessedClip out;
  out.clip.name = mirrored ? meta.name + "_mirrored" : meta.name;
  out.clip.source = meta.file.string();
  out.clip.loop = meta.loop;
  out.clip.mirrored = mirrored;
  out.clip.cost_multiplier = meta.cost_multiplier;
  out.clip.cost_bias = meta.cost_bias;
  out.clip.frame_count = motion.frame_count;
  out.tags = meta.tags;
  out.fps = motion.fps;
  out.flags.assign(motion.frame_count, 0);
  // Under Extrapolate, past_end marks only the phase windows that still clamp.
  if (settings.edge_rule != EdgeRule::Clamp) {
    for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
      if (raw->past_end[f]) out.flags[f] |= kFrameEdgeExcluded;
    }
  }
  // Extrapolate keeps the end's frames, but not the last few: a character
  // sent there would reach the end (and search again) at once.
  if (settings.edge_rule == EdgeRule::Extrapolate && !meta.loop) {
    const std::uint32_t keep_out = std::min(offset_frames(kExtrapolateEndSeconds, motion.fps), motion.frame_count);
    for (std::uint32_t f = motion.frame_count - keep_out; f < motion.frame_count; ++f) out.flags[f] |= kFrameEdgeExcluded;
  }
  flag_ranges(meta.do_not_use, motion.fps, kFrameDoNotUse, out.flags);
  flag_ranges(meta.block_transition, motion.fps, kFrameBlockTransition, out.flags);
  MMVK_TRY(apply_time_ranges(meta, motion.frame_count, motion.fps, out));
  if (settings.gait_bands.enabled) out.gait = measure_gait_tags(root->positions, motion.fps, meta.loop, settings.gait_bands);
  out.raw = std::move(*raw);
  if (settings.animation.enabled) {
    Result<detail::ClipAnimation> animation =
        detail::extract_clip_animation(motion, *root, settings.character_root.source_bone,
                                       settings.contacts, source);
    if (!animation.ok()) return animation.error();
    out.animation = std::move(*animation);
  }
  return out;
}

bool same_rate(float a, float b) { return std::abs(a - b) <= 1e-3f * std::max(a, b); }

// Frames [first, first + count) of a motion and of its sidecar arrays.
void keep_frames(Motion& motion, std::vector<std::vector<float>>& custom, std::uint32_t first, std::uint32_t count) {
  const std::size_t joints = motion.joint_count();
  auto keep = [&](auto& values, std::size_t per_frame) {
    values.erase(values.begin() + std::ptrdiff_t((first + count) * per_frame), values.end());
    values.erase(values.begin(), values.begin() + std::ptrdiff_t(first * per_frame));
  };
  keep(motion.local_positions, joints);
  keep(motion.local_rotations, joints);
  for (std::vector<float>& values : custom) keep(values, values.size() / motion.frame_count);
  motion.frame_count = count;
}

// The clips' poses as the database's animation; mixed skeletons are valid
// for the features: the database is then built without poses and the
// caller is told why.
void add_animation(std::vector<ProcessedClip>& clips, const FootContactParams& contacts,
                   const AnimationBuildOptions& animation, std::span<const BonePair> mirror_bones,
                   const std::string& source, DatabaseParts& parts) {
  if (!animation.enabled) {
    parts.no_animation_reason = "built with --no-animation";
    return;
  }
  std::vector<detail::ClipAnimation> animations;
  animations.reserve(clips.size());
  for (ProcessedClip& clip : clips) animations.push_back(std::move(clip.animation));
  Result<AnimationData> data = detail::assemble_animation(animations, contacts, animation.encoding, mirror_bones);
  if (data.ok()) {
    parts.animation = std::move(*data);
    return;
  }
  parts.no_animation_reason = data.message();
  if (animation.warning) animation.warning(source + ": no animation section: " + data.message());
}

// A clip's per-frame tags and costs. They are stored only when some clip has
// time ranges (`per_frame`); the first such clip fills them in for the clips
// before it.
Status add_frame_modifiers(const ProcessedClip& processed, const Clip& clip, const std::string& source,
                           bool& per_frame, DatabaseParts& parts) {
  const bool ranged = !processed.tag_ranges.empty() || !processed.multiplier.empty();
  if (ranged && !per_frame) {
    per_frame = true;
    for (const Clip& before : parts.clips) {
      parts.frame_tags.insert(parts.frame_tags.end(), before.frame_count, before.tags);
      parts.frame_multiplier.insert(parts.frame_multiplier.end(), before.frame_count, before.cost_multiplier);
      parts.frame_bias.insert(parts.frame_bias.end(), before.frame_count, before.cost_bias);
    }
  }
  if (!per_frame) return {};
  const std::size_t first = parts.frame_tags.size();
  parts.frame_tags.insert(parts.frame_tags.end(), clip.frame_count, clip.tags);
  for (const TagRange& range : processed.tag_ranges) {
    MMVK_ASSIGN_OR_RETURN(const std::size_t index, tag_index(parts.tag_names, range.tag, source, clip.name));
    for (std::uint32_t f = 0; f < clip.frame_count; ++f) {
      if (in_range(f, processed.fps, range.range)) parts.frame_tags[first + f] |= TagMask{1} << index;
    }
  }
  if (processed.multiplier.empty()) {
    parts.frame_multiplier.insert(parts.frame_multiplier.end(), clip.frame_count, clip.cost_multiplier);
    parts.frame_bias.insert(parts.frame_bias.end(), clip.frame_count, clip.cost_bias);
  } else {
    parts.frame_multiplier.insert(parts.frame_multiplier.end(), processed.multiplier.begin(), processed.multiplier.end());
    parts.frame_bias.insert(parts.frame_bias.end(), processed.bias.begin(), processed.bias.end());
  }
  return {};
}

// The measured gait tags (gait_bands.hpp), numbered after the clips' own,
// on every frame; the database then keeps per-frame tags.
Status add_gait_tags(const std::vector<ProcessedClip>& clips, const GaitBandParams& params, const std::string& source,
                     DatabaseParts& parts) {
  if (!params.enabled) return {};
  if (parts.tag_names.size() + kGaitTagNames.size() > kMaxTags) {
    return make_error(source + ": " + std::to_string(parts.tag_names.size()) + " tags and the " +
                      std::to_string(kGaitTagNames.size()) + " measured gait tags are more than " +
                      std::to_string(kMaxTags) + " distinct tags; use fewer tags or turn the measured ones off "
                      "(\"gait_bands\": {\"enabled\": false})");
  }
  std::array<TagMask, kGaitTagNames.size()> bits{};
  for (std::size_t i = 0; i < kGaitTagNames.size(); ++i) {
    bits[i] = TagMask{1} << parts.tag_names.size();
    parts.tag_names.emplace_back(kGaitTagNames[i]);
  }
  if (parts.frame_tags.empty()) {
    for (const Clip& clip : parts.clips) {
      parts.frame_tags.insert(parts.frame_tags.end(), clip.frame_count, clip.tags);
      parts.frame_multiplier.insert(parts.frame_multiplier.end(), clip.frame_count, clip.cost_multiplier);
      parts.frame_bias.insert(parts.frame_bias.end(), clip.frame_count, clip.cost_bias);
    }
  }
  for (std::size_t c = 0; c < clips.size(); ++c) {
    const std::uint32_t first = parts.clips[c].first_frame;
    for (std::size_t f = 0; f < clips[c].gait.size(); ++f) {
      for (std::size_t i = 0; i < bits.size(); ++i) {
        if ((clips[c].gait[f] >> i) & 1u) parts.frame_tags[first + f] |= bits[i];
      }
    }
  }
  parts.gait_bands = params;
  return {};
}

// Concatenates processed clips, normalizes and creates the Database.
Result<Database> assemble(std::vector<ProcessedClip>& clips, const FeatureSchema& schema, float fps,
                          const FootContactParams& contacts, const GaitBandParams& gait_bands,
                          const AnimationBuildOptions& animation, std::span<const BonePair> mirror_bones,
                          const std::string& source, const std::string& crowd_settings) {
  if (clips.empty()) return make_error(source + ": no clips");
  DatabaseParts parts;
  parts.crowd_settings = crowd_settings;
  parts.schema = schema;
  parts.fps = fps;
  const std::uint32_t dims = schema.dims();
  std::uint64_t frames = 0;
  for (const ProcessedClip& clip : clips) frames += clip.clip.frame_count;
  if (frames > 0xFFFFFFF0u) return make_error(source + ": too many frames (" + std::to_string(frames) + ")");
  parts.features.reserve(frames * dims);
  parts.frame_flags.reserve(frames);
  add_animation(clips, contacts, animation, mirror_bones, source, parts);
  bool per_frame = false;  // per-frame tags and costs are stored (some clip has time ranges)
  for (ProcessedClip& processed : clips) {
    Clip clip = processed.clip;
    clip.first_frame = static_cast<std::uint32_t>(parts.frame_flags.size());
    for (const std::string& tag : processed.tags) {
      MMVK_ASSIGN_OR_RETURN(const std::size_t index, tag_index(parts.tag_names, tag, source, clip.name));
      clip.tags |= TagMask{1} << index;
    }
    MMVK_TRY(add_frame_modifiers(processed, clip, source, per_frame, parts));
    parts.features.insert(parts.features.end(), processed.raw.values.begin(), processed.raw.values.end());
    parts.frame_flags.insert(parts.frame_flags.end(), processed.flags.begin(), processed.flags.end());
    parts.clips.push_back(std::move(clip));
    // Free each clip's raw copy as soon as it is concatenated.
    processed.raw = {};
    processed.flags = {};
  }
  MMVK_TRY(add_gait_tags(clips, gait_bands, source, parts));
  Result<std::vector<DimNormalization>> normalization = compute_normalization(schema, parts.features);
  if (!normalization.ok()) return make_error(source + ": " + normalization.message());
  parts.normalization = std::move(*normalization);
  apply_normalization(parts.normalization, parts.features);
  const std::uint32_t never = kFrameDoNotUse | kFrameEdgeExcluded | kFrameBlockTransition;
  if (std::all_of(parts.frame_flags.begin(), parts.frame_flags.end(), [&](std::uint32_t f) { return (f & never) != 0; })) {
    return make_error(source + ": no frame of the " + std::to_string(frames) +
                      " can be jumped to (every one is do-not-use, block-transition or edge-excluded); "
                      "check the clips' time ranges, or their length against the longest trajectory offset");
  }
  Result<Database> database = Database::create(std::move(parts));
  if (!database.ok()) return make_error(source + ": " + database.message());
  return database;
}

// Everything one manifest clip turns into: the clip and maybe its mirror.
struct LoadedClip {
  std::optional<Error> error;
  float source_fps = 0.0f;
  std::vector<ProcessedClip> clips;
};

// Applies the manifest's mirror map to the clip's sidecar values (in
// place: the mirrored copy is the last user).
void mirror_sidecars(const Manifest& manifest, std::vector<std::vector<float>>& custom) {
  for (std::size_t i = 0, c = 0; c < manifest.schema.channels.size(); ++c) {
    const FeatureChannel& channel = manifest.schema.channels[c];
    if (!reads_sidecar(channel.kind)) continue;
    std::vector<float>& values = custom[i++];
    for (const SidecarMirror& map : manifest.mirror_map) {
      if (map.channel != channel.name) continue;
      const std::size_t dims = channel.custom_dims;
      std::vector<float> row(dims);
      for (std::size_t f = 0; f < values.size() / dims; ++f) {
        float* frame = values.data() + f * dims;
        for (std::size_t d = 0; d < dims; ++d) row[d] = map.sign[d] * frame[map.source[d]];
        std::copy(row.begin(), row.end(), frame);
      }
    }
  }
}

bool tagged_walk(const ManifestClip& meta) {
  return std::find(meta.tags.begin(), meta.tags.end(), "walk") != meta.tags.end();
}

// The import's plausibility (import_check.hpp), unless the manifest accepts
// whatever it measures.
Status check_plausible_import(const Manifest& manifest, const Motion& motion, const ImportContext& context) {
  if (manifest.import.accept_implausible) return {};
  return check_import(measure_import(motion), context);
}

// One motion a clip's file holds: a BVH's, or one animation of a scene file.
struct SourceMotion {
  std::string animation;  // the scene animation's name; empty for BVH
  Motion motion;
  float metres_per_unit = 0.0f;
  std::string units_from, axes_from;  // ImportContext's, kept on the clip for `mmvk inspect`
};

// The motions of a manifest clip's file: one for a BVH; one per animation
// (or the one the clip names) for FBX, glTF and COLLADA, sampled at the
// manifest's fps.
Result<std::vector<SourceMotion>> import_clip_file(const Manifest& manifest, const ManifestClip& meta) {
  std::vector<SourceMotion> motions;
  if (is_scene_path(meta.file)) {
    SceneImportOptions options;
    options.import = manifest.import;
    options.fps = manifest.fps;
    options.animation = meta.animation;
    MMVK_ASSIGN_OR_RETURN(SceneImport scene, import_scene(meta.file, options));
    for (SceneAnimation& animation : scene.animations) {
      const ImportContext context{meta.file.string() + " (animation '" + animation.name + "')", scene.metres_per_unit,
                                  scene.units_from, manifest.import.up_axis, scene.axes_from, tagged_walk(meta)};
      MMVK_TRY(check_plausible_import(manifest, animation.motion, context));
      motions.push_back({std::move(animation.name), std::move(animation.motion), scene.metres_per_unit,
                         scene.units_from, scene.axes_from});
    }
    return motions;
  }
  if (!meta.animation.empty()) {
    return make_error(meta.file.string() + ": \"animation\" names an animation of an FBX, glTF or COLLADA file; "
                      "a BVH holds one motion");
  }
  Result<BvhFile> bvh = load_bvh(meta.file);
  if (!bvh.ok()) return bvh.error();
  Result<Motion> motion = motion_from_bvh(*bvh, manifest.import);
  if (!motion.ok()) return motion.error();
  // The units the import used, recorded so that `mmvk inspect` can show them.
  const float units = manifest.import.metres_per_unit > 0.0f ? manifest.import.metres_per_unit
                                                             : guess_metres_per_unit(*bvh);
  const bool given_axis = manifest.import.up_axis_given;
  const ImportContext context{
      meta.file.string(), units,
      manifest.import.metres_per_unit > 0.0f ? "the manifest's import.metres_per_unit" : "guessed from the skeleton's size",
      manifest.import.up_axis,
      given_axis ? std::string("the manifest's import.up_axis") : std::string("BVH files are read Y-up unless told"),
      tagged_walk(meta)};
  MMVK_TRY(check_plausible_import(manifest, *motion, context));
  motions.push_back({"", std::move(*motion), units, context.units_from, context.axes_from});
  return motions;
}

// What the import of `source` used, recorded on its clip.
void record_import(const SourceMotion& source, Clip& clip) {
  clip.metres_per_unit = source.metres_per_unit;
  clip.units_from = source.units_from;
  clip.axes_from = source.axes_from;
}

// The clip of one motion of the file (and its mirror) appended to `out`.
Status load_motion(const Manifest& manifest, const ManifestClip& meta, SourceMotion& source,
                   const AnimationBuildOptions& animation, LoadedClip& out) {
  std::optional<Motion> motion(std::move(source.motion));
  out.source_fps = motion->fps;
  const std::uint32_t source_frames = motion->frame_count;
  std::vector<std::vector<float>> custom;
  for (const FeatureChannel& channel : manifest.schema.channels) {
    if (!reads_sidecar(channel.kind)) continue;
    if (is_scene_path(meta.file)) {
      return make_error(meta.file.string() + ": channel '" + channel.name +
                        "' reads a sidecar file, which only BVH clips have");
    }
    MMVK_ASSIGN_OR_RETURN(std::vector<float> values, load_custom_sidecar(meta.file, channel, source_frames));
    custom.push_back(std::move(values));
  }
  if (manifest.fps > 0.0f && !same_rate(manifest.fps, motion->fps)) {
    Result<Motion> resampled = resample(*motion, manifest.fps);
    if (!resampled.ok()) return make_error(meta.file.string() + ": " + resampled.message());
    for (std::size_t i = 0, c = 0; c < manifest.schema.channels.size(); ++c) {
      const FeatureChannel& channel = manifest.schema.channels[c];
      if (!reads_sidecar(channel.kind)) continue;
      custom[i] = resample_values(custom[i], channel.custom_dims, source_frames, motion->fps,
                                  resampled->frame_count, resampled->fps);
      ++i;
    }
    motion = std::move(*resampled);
  }
  if (meta.range) {
    // The part of the file the clip takes, at the build's rate.
    const std::string field = (meta.field.empty() ? meta.file.string() + ": clip '" + meta.name + "'" : meta.field) +
                              ".range";
    MMVK_TRY(check_inside(*meta.range, motion->frame_count, motion->fps, field));
    std::uint32_t first = motion->frame_count, end = 0;
    for (std::uint32_t f = 0; f < motion->frame_count; ++f) {
      if (in_range(f, motion->fps, *meta.range)) first = std::min(first, f), end = f + 1;
    }
    keep_frames(*motion, custom, first, end - first);
  }
  const MotionBuildSettings settings{manifest.schema, manifest.character_root, manifest.edge_rule, animation,
                                     manifest.contacts, manifest.gait_bands};
  MMVK_ASSIGN_OR_RETURN(ProcessedClip processed, process_motion(meta, *motion, custom, false, settings));
  record_import(source, processed.clip);
  out.clips.push_back(std::move(processed));
  if (!meta.mirror) return {};
  Result<Motion> mirrored = mirror(*motion, manifest.mirror_bones);
  if (!mirrored.ok()) {
    return make_error((manifest.mirror_bones.empty() ? "" : manifest.source + ": ") + meta.file.string() +
                      ": mirroring: " + mirrored.message());
  }
  mirror_sidecars(manifest, custom);
  MMVK_ASSIGN_OR_RETURN(ProcessedClip processed_mirror, process_motion(meta, *mirrored, custom, true, settings));
  record_import(source, processed_mirror.clip);
  out.clips.push_back(std::move(processed_mirror));
  return {};
}

LoadedClip load_clip(const Manifest& manifest, const ManifestClip& meta, const AnimationBuildOptions& animation) {
  LoadedClip out;
  Result<std::vector<SourceMotion>> motions = import_clip_file(manifest, meta);
  if (!motions.ok()) {
    out.error = motions.error();
    return out;
  }
  for (SourceMotion& source : *motions) {
    // Several animations of one file are several clips, named after them
    // (an unnamed one after the file and its place in it).
    ManifestClip named = meta;
    if (motions->size() > 1) {
      named.name = source.animation.empty() ? meta.name + "_" + std::to_string(&source - motions->data())
                                            : source.animation;
    }
    Status loaded = load_motion(manifest, named, source, animation, out);
    if (!loaded.ok()) {
      const std::string which = source.animation.empty() ? "" : " (animation '" + source.animation + "')";
      out.error = make_error(loaded.message() + which);
      return out;
    }
  }
  return out;
}

}  // namespace

Result<Database> build_database(const Manifest& manifest, const BuildOptions& options) {
  const std::string& source = manifest.source.empty() ? std::string("manifest") : manifest.source;
  {
    Status valid = manifest.schema.validate();
    if (!valid.ok()) return make_error(source + ": " + valid.message());
  }
  MMVK_TRY(validate_foot_contact_params(manifest.contacts, source + ": contacts"));
  MMVK_TRY(validate_gait_band_params(manifest.gait_bands, source + ": gait_bands"));
  if (manifest.clips.empty()) return make_error(source + ": no clips");
  // 0 keeps the source rate; anything else is a resampling target (the
  // manifest parser checks this too, but --fps overrides it afterwards).
  if (manifest.fps != 0.0f && !(manifest.fps >= kMinFps && manifest.fps <= kMaxFps)) {
    char text[160];
    std::snprintf(text, sizeof(text), ": fps %g is outside the supported [%g, %g] frames/s", double(manifest.fps),
                  double(kMinFps), double(kMaxFps));
    return make_error(source + text);
  }
  const std::size_t count = manifest.clips.size();
  std::vector<LoadedClip> loaded(count);
  std::atomic<std::size_t> next{0};
  std::mutex progress_mutex;
  BuildProgress progress;
  progress.clip_count = count;
  // Threads pull clips one at a time: clip lengths vary a lot, so fixed
  // chunks would leave a thread idle.
  auto worker = [&](std::size_t, std::size_t, unsigned) {
    for (std::size_t i = next++; i < count; i = next++) {
      loaded[i] = load_clip(manifest, manifest.clips[i], options.animation);
      if (options.progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        ++progress.clips_done;
        for (const ProcessedClip& clip : loaded[i].clips) progress.frames_done += clip.clip.frame_count;
        options.progress(progress);
      }
    }
  };
  if (options.pool) {
    options.pool->parallel_for(options.pool->thread_count(), worker);
  } else {
    worker(0, 1, 0);
  }
  for (const LoadedClip& clip : loaded) {
    if (clip.error) return make_error(clip.error->message);
  }
  float fps = manifest.fps;
  if (!(fps > 0.0f)) {
    fps = loaded[0].source_fps;
    for (std::size_t i = 1; i < count; ++i) {
      if (!same_rate(loaded[i].source_fps, fps)) {
        return make_error(source + ": mixed frame rates without resampling: " + manifest.clips[0].file.string() +
                          " is " + std::to_string(fps) + " fps, " + manifest.clips[i].file.string() + " is " +
                          std::to_string(loaded[i].source_fps) + " fps (set \"fps\" in the manifest or pass --fps)");
      }
    }
  }
  std::vector<ProcessedClip> clips;
  for (LoadedClip& clip : loaded) {
    for (ProcessedClip& processed : clip.clips) clips.push_back(std::move(processed));
    clip.clips.clear();
  }
  MMVK_ASSIGN_OR_RETURN(Database database,
                        assemble(clips, manifest.schema, fps, manifest.contacts, manifest.gait_bands, options.animation, manifest.mirror_bones, source,
                                 manifest.crowd));
  MMVK_TRY(detail::check_cost_overflow(database, source));
  return database;
}

Result<Database> build_database_from_motions(std::span<const MotionClip> clips, const MotionBuildSettings& settings) {
  MMVK_TRY(settings.schema.validate());
  MMVK_TRY(validate_foot_contact_params(settings.contacts, "build_database_from_motions: contacts"));
  MMVK_TRY(validate_gait_band_params(settings.gait_bands, "build_database_from_motions: gait_bands"));
  if (clips.empty()) return make_error("build_database_from_motions: no clips");
  const float fps = clips[0].motion.fps;
  std::vector<ProcessedClip> processed;
  for (const MotionClip& clip : clips) {
    if (!same_rate(clip.motion.fps, fps)) {
      return make_error(clip.meta.file.string() + ": " + std::to_string(clip.motion.fps) + " fps, the first clip (" +
                        clips[0].meta.file.string() + ") is " + std::to_string(fps) + " fps");
    }
    Result<ProcessedClip> one = process_motion(clip.meta, clip.motion, clip.custom, clip.mirrored, settings);
    if (!one.ok()) return one.error();
    processed.push_back(std::move(*one));
  }
  MMVK_ASSIGN_OR_RETURN(Database database, assemble(processed, settings.schema, fps, settings.contacts, settings.gait_bands,
                                                    settings.animation, {}, "build_database_from_motions", ""));
  MMVK_TRY(detail::check_cost_overflow(database, "build_database_from_motions"));
  return database;
}

}  // namespace mmvk
