#include "mmvk/database/gait_bands.hpp"

#include <algorithm>
#include <cmath>

#include "mmvk/common/number_text.hpp"

namespace mmvk {

namespace {

std::array<float, 3> thresholds(const GaitBandParams& params) {
  return {params.walk_from_mps, params.jog_from_mps, params.run_from_mps};
}

constexpr const char* kThresholdNames[] = {"walk_from_mps", "jog_from_mps", "run_from_mps"};

// The root position of frame g, which may lie past a looping clip's ends:
// the loop repeats displaced by its ground motion per cycle (frame 0 to the
// frame after the last: the clip's travel plus one mean step).
glm::vec3 unwrapped_root(std::span<const glm::vec3> root, std::ptrdiff_t g) {
  const std::ptrdiff_t n = std::ptrdiff_t(root.size());
  const std::ptrdiff_t cycle = g >= 0 ? g / n : -((n - 1 - g) / n);
  const glm::vec3 travel = n > 1 ? (root.back() - root.front()) * (float(n) / float(n - 1)) : glm::vec3(0.0f);
  return root[std::size_t(g - cycle * n)] + float(cycle) * travel;
}

// Frame f's horizontal root speed by central differences (one-sided at a
// non-looping clip's ends).
float root_speed(std::span<const glm::vec3> root, float fps, bool loop, std::size_t f) {
  const std::ptrdiff_t n = std::ptrdiff_t(root.size()), at = std::ptrdiff_t(f);
  const std::ptrdiff_t before = loop ? at - 1 : std::max<std::ptrdiff_t>(at - 1, 0);
  const std::ptrdiff_t after = loop ? at + 1 : std::min<std::ptrdiff_t>(at + 1, n - 1);
  if (after == before) return 0.0f;
  const glm::vec3 delta = unwrapped_root(root, after) - unwrapped_root(root, before);
  return std::hypot(delta.x, delta.z) * fps / float(after - before);
}

}  // namespace

Status validate_gait_band_params(const GaitBandParams& params, const std::string& where) {
  const auto values = thresholds(params);
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]) || !(values[i] > 0.0f)) {
      return make_error(where + "." + kThresholdNames[i] + ": must be a finite speed > 0 m/s, got " +
                        number_text(values[i]));
    }
    if (i > 0 && !(values[i] > values[i - 1])) {
      return make_error(where + "." + kThresholdNames[i] + ": must be above " + kThresholdNames[i - 1] + " (" +
                        number_text(values[i - 1]) + " m/s), got " + number_text(values[i]));
    }
  }
  const float h = params.hysteresis;
  if (!std::isfinite(h) || h < 0.0f || h >= 0.5f) {
    return make_error(where + ".hysteresis: must be a fraction in [0, 0.5), got " + number_text(h));
  }
  for (std::size_t i = 1; i < values.size(); ++i) {
    if (values[i - 1] * (1.0f + h) >= values[i] * (1.0f - h)) {
      return make_error(where + ".hysteresis: " + number_text(h) + " makes the margins of " + kThresholdNames[i - 1] +
                        " and " + kThresholdNames[i] + " overlap (" + number_text(values[i - 1]) + " x " +
                        number_text(1.0 + h) + " >= " + number_text(values[i]) + " x " + number_text(1.0 - h) +
                        "): lower it or move the thresholds apart");
    }
  }
  if (!std::isfinite(params.smoothing_seconds) || params.smoothing_seconds < 0.0f) {
    return make_error(where + ".smoothing_seconds: must be finite and >= 0, got " +
                      number_text(params.smoothing_seconds));
  }
  if (!std::isfinite(params.transition_seconds) || !(params.transition_seconds > 0.0f)) {
    return make_error(where + ".transition_seconds: must be finite and > 0, got " +
                      number_text(params.transition_seconds));
  }
  return {};
}

GaitBand gait_band_of_speed(const GaitBandParams& params, float speed_mps) {
  const auto values = thresholds(params);
  std::size_t band = 0;
  while (band < values.size() && speed_mps >= values[band]) ++band;
  return static_cast<GaitBand>(band);
}

std::vector<float> smoothed_root_speeds(std::span<const glm::vec3> root_positions, float fps, bool loop,
                                        float smoothing_seconds) {
  const std::size_t n = root_positions.size();
  std::vector<float> speed(n);
  for (std::size_t f = 0; f < n; ++f) speed[f] = root_speed(root_positions, fps, loop, f);
  const std::ptrdiff_t half = std::ptrdiff_t(std::lround(0.5 * double(smoothing_seconds) * double(fps)));
  if (half == 0 || n < 2) return speed;
  std::vector<float> smoothed(n);
  const std::ptrdiff_t count = std::ptrdiff_t(n);
  for (std::ptrdiff_t f = 0; f < count; ++f) {
    double sum = 0.0;
    int taken = 0;
    for (std::ptrdiff_t g = f - half; g <= f + half; ++g) {
      if (!loop && (g < 0 || g >= count)) continue;
      sum += speed[std::size_t(((g % count) + count) % count)];
      ++taken;
    }
    smoothed[std::size_t(f)] = float(sum / taken);
  }
  return smoothed;
}

std::vector<GaitTags> measure_gait_tags(std::span<const glm::vec3> root_positions, float fps, bool loop,
                                        const GaitBandParams& params) {
  const std::vector<float> speed = smoothed_root_speeds(root_positions, fps, loop, params.smoothing_seconds);
  const std::size_t n = speed.size();
  const auto values = thresholds(params);
  std::vector<std::size_t> band(n);
  for (std::size_t f = 0; f < n; ++f) {
    std::size_t b = f == 0 ? std::size_t(gait_band_of_speed(params, speed[0])) : band[f - 1];
    while (b < values.size() && speed[f] >= values[b] * (1.0f + params.hysteresis)) ++b;
    while (b > 0 && speed[f] < values[b - 1] * (1.0f - params.hysteresis)) --b;
    band[f] = b;
  }
  std::vector<GaitTags> tags(n);
  for (std::size_t f = 0; f < n; ++f) tags[f] = GaitTags(1u << band[f]);
  // Starts follow a stand, stops precede one, within the transition.
  const std::size_t reach = std::max<std::size_t>(1, std::size_t(std::lround(params.transition_seconds * fps)));
  const auto stands = [&](std::size_t f) { return band[f] == std::size_t(GaitBand::Stand); };
  for (std::size_t f = 0, last_stand = n; f < n; ++f) {
    if (stands(f)) {
      last_stand = f;
    } else if (last_stand < n && f - last_stand <= reach) {
      tags[f] |= GaitTags(1u << kGaitStartTag);
    }
  }
  for (std::size_t f = n, next_stand = n; f-- > 0;) {
    if (stands(f)) {
      next_stand = f;
    } else if (next_stand < n && next_stand - f <= reach) {
      tags[f] |= GaitTags(1u << kGaitStopTag);
    }
  }
  return tags;
}

}  // namespace mmvk
