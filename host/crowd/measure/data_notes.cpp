#include "measure/data_notes.hpp"

#include <algorithm>
#include <cstdio>

namespace mmvk::crowd {

namespace {

// "0.80" or "0.80-1.10": a range of speeds, m/s, as one number when it is one.
std::string speed_range(double min_mps, double max_mps) {
  char text[64];
  if (max_mps - min_mps < 0.005) {
    std::snprintf(text, sizeof(text), "%.2f", min_mps);
  } else {
    std::snprintf(text, sizeof(text), "%.2f-%.2f", min_mps, max_mps);
  }
  return text;
}

// The preferred speeds beyond `bound`: above it (faster) or below it.
struct Beyond {
  std::size_t characters = 0;
  double min_mps = 0.0, max_mps = 0.0;
};
Beyond speeds_beyond(std::span<const float> preferred_mps, double bound, bool faster) {
  Beyond beyond;
  for (const float speed : preferred_mps) {
    // A hundredth of a m/s of slack: a speed that prints as the bound is
    // not beyond it.
    if (faster ? double(speed) <= bound + 0.005 : double(speed) >= bound - 0.005) continue;
    beyond.min_mps = beyond.characters ? std::min(beyond.min_mps, double(speed)) : double(speed);
    beyond.max_mps = beyond.characters ? std::max(beyond.max_mps, double(speed)) : double(speed);
    ++beyond.characters;
  }
  return beyond;
}

void add_lacking_speed_notes(std::vector<std::string>& notes, const GaitCoverage& coverage,
                             const ControllerParams& params, std::span<const float> preferred_mps) {
  const PlayableSpeeds playable = playable_speeds(coverage, params);
  if (!playable.known || preferred_mps.empty()) return;
  const struct {
    bool faster;
    double bound_mps, percentile_mps;
    float rate, stride;
    const char *what, *side, *reach, *percentile;
  } sides[] = {
      {true, playable.max_mps, coverage.moving_p95_mps, params.max_play_rate, params.max_stride_scale, "faster",
       "above", "at most", "95th"},
      {false, playable.min_mps, coverage.moving_p5_mps, params.min_play_rate, params.min_stride_scale, "slower",
       "below", "at least", "5th"},
  };
  for (const auto& side : sides) {
    const Beyond beyond = speeds_beyond(preferred_mps, side.bound_mps, side.faster);
    if (beyond.characters == 0) continue;
    char text[512];
    std::snprintf(text, sizeof(text),
                  "the data lacks %s motion: the scenario asks %zu of %zu characters for %s m/s, %s the %.2f m/s its "
                  "moving frames play %s (%s percentile %.2f m/s x play rate %.2f x stride %.2f)",
                  side.what, beyond.characters, preferred_mps.size(), speed_range(beyond.min_mps, beyond.max_mps).c_str(),
                  side.side, side.bound_mps, side.reach, side.percentile, side.percentile_mps, double(side.rate),
                  double(side.stride));
    notes.push_back(text);
  }
}

}  // namespace

PlayableSpeeds playable_speeds(const GaitCoverage& coverage, const ControllerParams& params) {
  PlayableSpeeds playable;
  playable.known = coverage.measured && coverage.moving_p95_mps > 0.0f;
  if (!playable.known) return playable;
  playable.min_mps = double(coverage.moving_p5_mps) * double(params.min_play_rate) * double(params.min_stride_scale);
  playable.max_mps = double(coverage.moving_p95_mps) * double(params.max_play_rate) * double(params.max_stride_scale);
  return playable;
}

std::vector<std::string> data_notes(const GaitCoverage& coverage, const GaitBandParams* bands,
                                    const ControllerParams& params, std::span<const float> preferred_mps) {
  std::vector<std::string> notes;
  if (std::string idle = no_idle_note(coverage, bands); !idle.empty()) notes.push_back(std::move(idle));
  add_lacking_speed_notes(notes, coverage, params, preferred_mps);
  return notes;
}

std::vector<std::string> missed_speed_notes(const CommandFigures& c) {
  std::vector<std::string> notes;
  const struct {
    const CommandFigures::Missed& missed;
    const char* what;
  } kinds[] = {{c.too_fast, "slower"}, {c.too_slow, "faster"}};
  for (const auto& k : kinds) {
    if (k.missed.windows == 0) continue;
    char text[256];
    std::snprintf(text, sizeof(text),
                  "the data lacks %s motion: held commands of %s m/s played more than 20%% %s than asked "
                  "(%llu of %llu 1 s windows), beyond its play-rate and stride bounds",
                  k.what, speed_range(k.missed.min_mps, k.missed.max_mps).c_str(), k.what[0] == 's' ? "faster" : "slower",
                  static_cast<unsigned long long>(k.missed.windows), static_cast<unsigned long long>(c.windows));
    notes.push_back(text);
  }
  return notes;
}

}  // namespace mmvk::crowd
