#include "mmvk/database_build.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>

#include "mmvk/bvh.hpp"
#include "mmvk/character.hpp"
#include "mmvk/features.hpp"
#include "mmvk/normalization.hpp"
#include "database/animation_build.hpp"

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
};

void flag_ranges(std::span<const TimeRange> ranges, float fps, std::uint32_t flag, std::vector<std::uint32_t>& flags) {
  for (const TimeRange& range : ranges) {
    for (std::size_t f = 0; f < flags.size(); ++f) {
      const double t = static_cast<double>(f) / fps;
      if (t >= range.begin_seconds && t < range.end_seconds) flags[f] |= flag;
    }
  }
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
  if (settings.edge_rule == EdgeRule::Exclude) {
    for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
      if (raw->past_end[f]) out.flags[f] |= kFrameEdgeExcluded;
    }
  }
  flag_ranges(meta.do_not_use, motion.fps, kFrameDoNotUse, out.flags);
  flag_ranges(meta.block_transition, motion.fps, kFrameBlockTransition, out.flags);
  out.raw = std::move(*raw);
  if (settings.animation.enabled) {
    Result<detail::ClipAnimation> animation =
        detail::extract_clip_animation(motion, *root, settings.character_root.source_bone,
                                       settings.animation.contacts, source);
    if (!animation.ok()) return animation.error();
    out.animation = std::move(*animation);
  }
  return out;
}

bool same_rate(float a, float b) { return std::abs(a - b) <= 1e-3f * std::max(a, b); }

// Concatenates processed clips, normalizes and creates the Database.
Result<Database> assemble(std::vector<ProcessedClip>& clips, const FeatureSchema& schema, float fps,
                          const AnimationBuildOptions& animation, const std::string& source) {
  if (clips.empty()) return make_error(source + ": no clips");
  DatabaseParts parts;
  parts.schema = schema;
  parts.fps = fps;
  const std::uint32_t dims = schema.dims();
  std::uint64_t frames = 0;
  for (const ProcessedClip& clip : clips) frames += clip.clip.frame_count;
  if (frames > 0xFFFFFFF0u) return make_error(source + ": too many frames (" + std::to_string(frames) + ")");
  parts.features.reserve(frames * dims);
  parts.frame_flags.reserve(frames);
  if (animation.enabled) {
    std::vector<detail::ClipAnimation> animations;
    animations.reserve(clips.size());
    for (ProcessedClip& clip : clips) animations.push_back(std::move(clip.animation));
    Result<AnimationData> data = detail::assemble_animation(animations, animation.contacts, animation.encoding);
    if (data.ok()) {
      parts.animation = std::move(*data);
    } else if (animation.warning) {
      // Mixed skeletons are valid for the features: the database is built
      // without poses and the caller is told why.
      animation.warning(source + ": " + data.message());
    }
  }
  for (ProcessedClip& processed : clips) {
    Clip clip = processed.clip;
    clip.first_frame = static_cast<std::uint32_t>(parts.frame_flags.size());
    for (const std::string& tag : processed.tags) {
      auto it = std::find(parts.tag_names.begin(), parts.tag_names.end(), tag);
      std::size_t index = static_cast<std::size_t>(it - parts.tag_names.begin());
      if (it == parts.tag_names.end()) {
        if (parts.tag_names.size() == kMaxTags) {
          return make_error(source + ": more than " + std::to_string(kMaxTags) + " distinct tags (clip '" + clip.name +
                            "' adds '" + tag + "')");
        }
        parts.tag_names.push_back(tag);
      }
      clip.tags |= TagMask{1} << index;
    }
    parts.features.insert(parts.features.end(), processed.raw.values.begin(), processed.raw.values.end());
    parts.frame_flags.insert(parts.frame_flags.end(), processed.flags.begin(), processed.flags.end());
    parts.clips.push_back(std::move(clip));
    // Free each clip's raw copy as soon as it is concatenated.
    processed.raw = {};
    processed.flags = {};
  }
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

LoadedClip load_clip(const Manifest& manifest, const ManifestClip& meta, const AnimationBuildOptions& animation) {
  LoadedClip out;
  auto fail = [&](std::string message) {
    out.error = make_error(std::move(message));
    return std::move(out);
  };
  Result<BvhFile> bvh = load_bvh(meta.file);
  if (!bvh.ok()) return fail(bvh.message());
  Result<Motion> motion = motion_from_bvh(*bvh, manifest.import);
  if (!motion.ok()) return fail(motion.message());
  out.source_fps = motion->fps;
  const std::uint32_t source_frames = motion->frame_count;

  std::vector<std::vector<float>> custom;
  for (const FeatureChannel& channel : manifest.schema.channels) {
    if (!reads_sidecar(channel.kind)) continue;
    Result<std::vector<float>> values = load_custom_sidecar(meta.file, channel, source_frames);
    if (!values.ok()) return fail(values.message());
    custom.push_back(std::move(*values));
  }
  if (manifest.fps > 0.0f && !same_rate(manifest.fps, motion->fps)) {
    Result<Motion> resampled = resample(*motion, manifest.fps);
    if (!resampled.ok()) return fail(meta.file.string() + ": " + resampled.message());
    for (std::size_t i = 0, c = 0; c < manifest.schema.channels.size(); ++c) {
      const FeatureChannel& channel = manifest.schema.channels[c];
      if (!reads_sidecar(channel.kind)) continue;
      custom[i] = resample_values(custom[i], channel.custom_dims, source_frames, motion->fps,
                                  resampled->frame_count, resampled->fps);
      ++i;
    }
    motion = std::move(resampled);
  }
  const MotionBuildSettings settings{manifest.schema, manifest.character_root, manifest.edge_rule, animation};
  Result<ProcessedClip> processed = process_motion(meta, *motion, custom, false, settings);
  if (!processed.ok()) return fail(processed.message());
  out.clips.push_back(std::move(*processed));
  if (meta.mirror) {
    Result<Motion> mirrored = mirror(*motion);
    if (!mirrored.ok()) return fail(meta.file.string() + ": mirroring: " + mirrored.message());
    Result<ProcessedClip> processed_mirror = process_motion(meta, *mirrored, custom, true, settings);
    if (!processed_mirror.ok()) return fail(processed_mirror.message());
    out.clips.push_back(std::move(*processed_mirror));
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
  return assemble(clips, manifest.schema, fps, options.animation, source);
}

Result<Database> build_database_from_motions(std::span<const MotionClip> clips, const MotionBuildSettings& settings) {
  MMVK_TRY(settings.schema.validate());
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
  return assemble(processed, settings.schema, fps, settings.animation, "build_database_from_motions");
}

}  // namespace mmvk
