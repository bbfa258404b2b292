#include "mmvk/database/database.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "mmvk/common/hash.hpp"

namespace mmvk {

namespace {

// The optional per-frame tags, multipliers and biases of DatabaseParts.
Status validate_frame_modifiers(const DatabaseParts& parts, TagMask valid_tags) {
  const std::size_t frames = parts.frame_flags.size();
  auto sized = [&](std::size_t size, const char* what) -> Status {
    if (size == 0 || size == frames) return {};
    return make_error("database: " + std::string(what) + " has " + std::to_string(size) + " values for " +
                      std::to_string(frames) + " frames");
  };
  MMVK_TRY(sized(parts.frame_tags.size(), "per-frame tags"));
  MMVK_TRY(sized(parts.frame_multiplier.size(), "per-frame cost multiplier"));
  MMVK_TRY(sized(parts.frame_bias.size(), "per-frame cost bias"));
  for (std::size_t f = 0; f < parts.frame_tags.size(); ++f) {
    if ((parts.frame_tags[f] & ~valid_tags) != 0) {
      return make_error("database: frame " + std::to_string(f) + " has tag bits beyond the tag names");
    }
  }
  for (std::size_t f = 0; f < parts.frame_multiplier.size(); ++f) {
    const float m = parts.frame_multiplier[f];
    if (!(m > 0.0f) || !std::isfinite(m)) {
      return make_error("database: frame " + std::to_string(f) + ": cost multiplier must be finite and > 0");
    }
  }
  for (std::size_t f = 0; f < parts.frame_bias.size(); ++f) {
    if (!std::isfinite(parts.frame_bias[f])) {
      return make_error("database: frame " + std::to_string(f) + ": cost bias must be finite");
    }
  }
  return {};
}

// Measured gait tags need their parameters valid and their names present.
Status validate_gait_bands(const DatabaseParts& parts) {
  if (!parts.gait_bands) return {};
  MMVK_TRY(validate_gait_band_params(*parts.gait_bands, "database: gait_bands"));
  for (std::string_view name : kGaitTagNames) {
    if (std::find(parts.tag_names.begin(), parts.tag_names.end(), name) == parts.tag_names.end()) {
      return make_error("database: gait bands are set but the tag '" + std::string(name) + "' is missing");
    }
  }
  return {};
}

Status validate_parts(const DatabaseParts& parts) {
  MMVK_TRY(parts.schema.validate());
  MMVK_TRY(validate_gait_bands(parts));
  const std::uint32_t dims = parts.schema.dims();
  if (!(parts.fps > 0.0f) || !std::isfinite(parts.fps)) {
    return make_error("database: fps must be positive, got " + std::to_string(parts.fps));
  }
  if (parts.normalization.size() != dims) {
    return make_error("database: normalization has " + std::to_string(parts.normalization.size()) +
                      " dims, schema has " + std::to_string(dims));
  }
  for (std::uint32_t d = 0; d < dims; ++d) {
    const DimNormalization& n = parts.normalization[d];
    if (!std::isfinite(n.offset) || !std::isfinite(n.scale) || !(n.scale > 0.0f)) {
      return make_error("database: normalization of " + parts.schema.dim_name(d) +
                        " is invalid (offset " + std::to_string(n.offset) + ", scale " + std::to_string(n.scale) +
                        "); the scale must be finite and > 0");
    }
  }
  if (parts.tag_names.size() > kMaxTags) {
    return make_error("database: " + std::to_string(parts.tag_names.size()) + " tags, at most " +
                      std::to_string(kMaxTags) + " are supported");
  }
  std::set<std::string> seen_tags;
  for (const std::string& tag : parts.tag_names) {
    if (tag.empty()) return make_error("database: empty tag name");
    if (!seen_tags.insert(tag).second) return make_error("database: duplicate tag '" + tag + "'");
  }
  const TagMask valid_tags = parts.tag_names.size() == 64 ? ~TagMask{0} : (TagMask{1} << parts.tag_names.size()) - 1;
  const std::size_t frames = parts.frame_flags.size();
  if (frames > 0xFFFFFFF0u) return make_error("database: too many frames");
  if (parts.features.size() != frames * dims) {
    return make_error("database: feature matrix has " + std::to_string(parts.features.size()) + " values, expected " +
                      std::to_string(frames) + " frames x " + std::to_string(dims) + " dims");
  }
  std::uint64_t next_frame = 0;
  for (std::size_t c = 0; c < parts.clips.size(); ++c) {
    const Clip& clip = parts.clips[c];
    const std::string where = "database: clip " + std::to_string(c) + " ('" + clip.name + "')";
    if (clip.first_frame != next_frame) {
      return make_error(where + " starts at frame " + std::to_string(clip.first_frame) + ", expected " +
                        std::to_string(next_frame) + " (clips must be contiguous and in order)");
    }
    if (clip.frame_count == 0) return make_error(where + " has no frames");
    if (!(clip.cost_multiplier > 0.0f) || !std::isfinite(clip.cost_multiplier)) {
      return make_error(where + ": cost multiplier must be finite and > 0");
    }
    if (!std::isfinite(clip.cost_bias)) return make_error(where + ": cost bias must be finite");
    if (!(clip.metres_per_unit >= 0.0f) || !std::isfinite(clip.metres_per_unit)) {
      return make_error(where + ": metres per unit must be finite and >= 0");
    }
    if ((clip.tags & ~valid_tags) != 0) return make_error(where + " has tag bits beyond the tag names");
    next_frame += clip.frame_count;
  }
  if (next_frame != frames) {
    return make_error("database: clips cover " + std::to_string(next_frame) + " frames, the database has " +
                      std::to_string(frames));
  }
  MMVK_TRY(validate_frame_modifiers(parts, valid_tags));
  const std::uint32_t known_flags = kFrameDoNotUse | kFrameBlockTransition | kFrameEdgeExcluded;
  for (std::size_t f = 0; f < frames; ++f) {
    if ((parts.frame_flags[f] & ~known_flags) != 0) {
      return make_error("database: frame " + std::to_string(f) + " has unknown flag bits");
    }
  }
  for (std::size_t i = 0; i < parts.features.size(); ++i) {
    if (!std::isfinite(parts.features[i])) {
      return make_error("database: feature " + parts.schema.dim_name(static_cast<std::uint32_t>(i % dims)) +
                        " of frame " + std::to_string(i / dims) + " is not finite");
    }
  }
  if (parts.animation) {
    Status animation = parts.animation->validate(static_cast<std::uint32_t>(frames));
    if (!animation.ok()) return make_error("database: " + animation.message());
  }
  return {};
}

}  // namespace

Result<Database> Database::create(DatabaseParts parts) {
  MMVK_TRY(validate_parts(parts));
  return Database(std::move(parts));
}

Database::Database(DatabaseParts parts) : parts_(std::move(parts)) {
  frame_count_ = static_cast<std::uint32_t>(parts_.frame_flags.size());
  dims_ = parts_.schema.dims();
  frame_clip_.resize(frame_count_);
  frame_tags_.resize(frame_count_);
  frame_multiplier_.resize(frame_count_);
  frame_bias_.resize(frame_count_);
  for (std::uint32_t c = 0; c < parts_.clips.size(); ++c) {
    const Clip& clip = parts_.clips[c];
    for (std::uint32_t f = clip.first_frame; f < clip.first_frame + clip.frame_count; ++f) {
      frame_clip_[f] = c;
      frame_tags_[f] = clip.tags;
      frame_multiplier_[f] = clip.cost_multiplier;
      frame_bias_[f] = clip.cost_bias;
    }
  }
  if (!parts_.frame_tags.empty()) frame_tags_ = parts_.frame_tags;
  if (!parts_.frame_multiplier.empty()) frame_multiplier_ = parts_.frame_multiplier;
  if (!parts_.frame_bias.empty()) frame_bias_ = parts_.frame_bias;
  for (std::uint32_t f = 0; f < frame_count_; ++f) {
    max_multiplier_ = std::max(max_multiplier_, frame_multiplier_[f]);
    max_abs_bias_ = std::max(max_abs_bias_, std::fabs(frame_bias_[f]));
  }
  max_abs_features_.assign(dims_, 0.0f);
  for (std::size_t i = 0; i < parts_.features.size(); ++i) {
    float& bound = max_abs_features_[i % dims_];
    bound = std::max(bound, std::fabs(parts_.features[i]));
  }
  Hasher hasher;
  hasher.add(parts_.fps);
  hasher.add(dims_);
  hasher.add(frame_count_);
  for (const FeatureChannel& channel : parts_.schema.channels) hasher.add_bytes(channel.name.data(), channel.name.size());
  hasher.add_span(std::span<const DimNormalization>(parts_.normalization));
  hasher.add_span(std::span<const std::uint32_t>(parts_.frame_flags));
  hasher.add_span(std::span<const std::uint32_t>(frame_clip_));
  hasher.add_span(std::span<const TagMask>(frame_tags_));
  hasher.add_span(std::span<const float>(frame_multiplier_));
  hasher.add_span(std::span<const float>(frame_bias_));
  hasher.add_span(std::span<const float>(parts_.features));
  for (const Clip& clip : parts_.clips) hasher.add(clip.loop);
  content_hash_ = hasher.digest();
}

Result<TagMask> Database::tag_mask(std::span<const std::string> names) const {
  TagMask mask = 0;
  for (const std::string& name : names) {
    bool found = false;
    for (std::size_t t = 0; t < parts_.tag_names.size(); ++t) {
      if (parts_.tag_names[t] == name) {
        mask |= TagMask{1} << t;
        found = true;
      }
    }
    if (!found) {
      std::string known;
      for (const std::string& tag : parts_.tag_names) known += (known.empty() ? "" : ", ") + tag;
      return make_error("unknown tag '" + name + "': " +
                        (known.empty() ? std::string("the database has no tags (a manifest's clips give them)")
                                       : "the database's tags are " + known + " (exact, case-sensitive)"));
    }
  }
  return mask;
}

void Database::normalize(std::span<const float> raw, std::span<float> out) const {
  for (std::uint32_t d = 0; d < dims_; ++d) {
    out[d] = (raw[d] - parts_.normalization[d].offset) / parts_.normalization[d].scale;
  }
}

}  // namespace mmvk
