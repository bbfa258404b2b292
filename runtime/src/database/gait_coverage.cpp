#include "mmvk/database/gait_coverage.hpp"

#include <algorithm>
#include <cstdio>
#include <span>
#include <vector>

#include "mmvk/features/foot_contacts.hpp"
#include "mmvk/common/number_text.hpp"

namespace mmvk {

namespace {

constexpr std::uint32_t kNotCandidate = kFrameDoNotUse | kFrameEdgeExcluded;

// The frames a coverage counts: candidates that the caller's tags allow.
struct Candidates {
  const Database& database;
  TagMask require_all, exclude_any;
  bool operator()(std::uint32_t frame) const {
    if (database.frame_flags()[frame] & kNotCandidate) return false;
    const TagMask tags = database.frame_tags()[frame];
    return (tags & require_all) == require_all && (tags & exclude_any) == 0;
  }
};

// The smoothed root speeds of the candidate moving frames, clip by clip.
std::vector<float> moving_speeds(const Candidates& candidate, const GaitBandParams& params, TagMask stand) {
  const Database& database = candidate.database;
  std::vector<float> moving;
  const AnimationData* animation = database.animation();
  if (!animation) return moving;
  for (const Clip& clip : database.clips()) {
    const std::span<const glm::vec3> root(animation->root_positions.data() + clip.first_frame, clip.frame_count);
    const std::vector<float> speeds = smoothed_root_speeds(root, database.fps(), clip.loop, params.smoothing_seconds);
    for (std::uint32_t f = 0; f < clip.frame_count; ++f) {
      const std::uint32_t frame = clip.first_frame + f;
      if (!candidate(frame) || (database.frame_tags()[frame] & stand)) continue;
      moving.push_back(speeds[f]);
    }
  }
  return moving;
}

// The longest run of consecutive stand candidates in one clip, and whether
// a looping clip stands throughout.
void measure_idles(const Candidates& candidate, TagMask stand, GaitCoverage& coverage) {
  const Database& database = candidate.database;
  for (const Clip& clip : database.clips()) {
    std::uint32_t run = 0, longest = 0;
    for (std::uint32_t f = clip.first_frame; f < clip.first_frame + clip.frame_count; ++f) {
      const bool stands = candidate(f) && (database.frame_tags()[f] & stand);
      run = stands ? run + 1 : 0;
      longest = std::max(longest, run);
    }
    coverage.longest_stand_seconds = std::max(coverage.longest_stand_seconds, float(longest) / database.fps());
    coverage.stand_loop = coverage.stand_loop || (clip.loop && clip.frame_count > 0 && longest == clip.frame_count);
  }
}

std::string yes_no(bool value) { return value ? "yes" : "no"; }

}  // namespace

GaitTagBits gait_tag_bits(const Database& database) {
  GaitTagBits bits;
  const auto names = database.tag_names();
  for (std::size_t i = 0; i < kGaitTagNames.size(); ++i) {
    const auto it = std::find(names.begin(), names.end(), kGaitTagNames[i]);
    if (it != names.end()) bits.bit[i] = TagMask{1} << std::size_t(it - names.begin());
    bits.all |= bits.bit[i];
  }
  return bits;
}

GaitCoverage measure_gait_coverage(const Database& database, TagMask require_all, TagMask exclude_any) {
  GaitCoverage coverage;
  const GaitBandParams* params = database.gait_bands();
  if (!params) return coverage;
  coverage.measured = true;
  const auto bits = gait_tag_bits(database).bit;
  const Candidates candidate{database, require_all, exclude_any};
  const AnimationData* animation = database.animation();
  coverage.has_contacts = animation != nullptr && !animation->contacts.empty();
  for (std::uint32_t f = 0; f < database.frame_count(); ++f) {
    if (!candidate(f)) continue;
    const TagMask tags = database.frame_tags()[f];
    for (std::size_t b = 0; b < kGaitBandCount; ++b) coverage.band_frames[b] += (tags & bits[b]) != 0;
    coverage.start_frames += (tags & bits[kGaitStartTag]) != 0;
    coverage.stop_frames += (tags & bits[kGaitStopTag]) != 0;
    const bool stands = (tags & bits[std::size_t(GaitBand::Stand)]) != 0;
    if (stands && coverage.has_contacts && both_feet_planted(animation->contacts[f])) {
      ++coverage.stand_both_feet_frames;
    }
  }
  measure_idles(candidate, bits[std::size_t(GaitBand::Stand)], coverage);
  std::vector<float> moving = moving_speeds(candidate, *params, bits[std::size_t(GaitBand::Stand)]);
  if (!moving.empty()) {
    std::sort(moving.begin(), moving.end());
    const auto at = [&](double q) { return moving[std::min(moving.size() - 1, std::size_t(q * double(moving.size())))]; };
    coverage.moving_p5_mps = at(0.05);
    coverage.moving_p95_mps = at(0.95);
  }
  return coverage;
}

std::string gait_capabilities(const GaitCoverage& coverage) {
  if (!coverage.measured) return "not measured (a database built before format 7, or with gait_bands off)";
  std::string bands;
  for (std::size_t b = std::size_t(GaitBand::Walk); b < kGaitBandCount; ++b) {
    if (coverage.band_frames[b] == 0) continue;
    bands += (bands.empty() ? "" : ", ") + std::string(kGaitTagNames[b].substr(kGaitTagPrefix.size()));
  }
  return "stands: " + yes_no(coverage.can_stand()) +
         ", starts: " + yes_no(coverage.start_frames > 0) + ", stops: " + yes_no(coverage.stop_frames > 0) +
         ", speeds: " + (bands.empty() ? "none" : bands);
}

std::string describe_gait_coverage(const GaitCoverage& coverage, const GaitBandParams* params) {
  if (!coverage.measured || !params) return gait_capabilities(coverage);
  char text[512];
  const auto& n = coverage.band_frames;
  std::snprintf(text, sizeof(text),
                "candidate frames by root speed: stand %llu (under %g m/s), walk %llu, jog %llu (from %g m/s), "
                "run %llu (from %g m/s); start %llu, stop %llu",
                static_cast<unsigned long long>(n[0]), double(params->walk_from_mps),
                static_cast<unsigned long long>(n[1]), static_cast<unsigned long long>(n[2]),
                double(params->jog_from_mps), static_cast<unsigned long long>(n[3]), double(params->run_from_mps),
                static_cast<unsigned long long>(coverage.start_frames),
                static_cast<unsigned long long>(coverage.stop_frames));
  std::string out = text;
  if (coverage.moving_p95_mps > 0.0f) {
    std::snprintf(text, sizeof(text), "; moving at %.2f-%.2f m/s (5th-95th percentile)", double(coverage.moving_p5_mps),
                  double(coverage.moving_p95_mps));
    out += text;
  }
  if (const std::string idle = no_idle_note(coverage, params); !idle.empty()) out += "\n" + idle;
  if (n[0] > 0 && coverage.has_contacts) {
    out += "\nstanding frames with both feet planted: " + std::to_string(coverage.stand_both_feet_frames) + " of " +
           std::to_string(n[0]);
  }
  return out;
}

std::string no_idle_note(const GaitCoverage& coverage, const GaitBandParams* params) {
  const char* const holds = "a character told to stop or stand must hold a frame instead";
  if (!coverage.measured || !params) {
    return "the data has no idle: its gait tags are " + gait_capabilities(coverage) +
           ", so no frame is known to stand; " + holds;
  }
  if (coverage.can_stand()) return {};
  char text[512];
  std::snprintf(text, sizeof(text),
                "the data has no idle: %llu candidate frames stand (root under %g m/s), the longest run %.2f s, "
                "and no looping clip stands (an idle needs %g s or a standing loop); %s",
                static_cast<unsigned long long>(coverage.band_frames[0]), double(params->walk_from_mps),
                double(coverage.longest_stand_seconds), double(kMinIdleSeconds), holds);
  return text;
}

}  // namespace mmvk
