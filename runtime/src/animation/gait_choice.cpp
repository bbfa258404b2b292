#include "mmvk/animation/gait_choice.hpp"

#include <algorithm>

namespace mmvk {

namespace {

// The threshold at which band b starts (b > Stand).
float band_start(const GaitBandParams& p, std::size_t b) {
  const float starts[kGaitBandCount] = {0.0f, p.walk_from_mps, p.jog_from_mps, p.run_from_mps};
  return starts[b];
}

// Step 1: the band of `speed` as left from `band` with hysteresis.
GaitBand banded(const GaitBandParams& p, GaitBand band, float speed) {
  auto b = std::size_t(band);
  while (b + 1 < kGaitBandCount && speed >= band_start(p, b + 1) * (1.0f + p.hysteresis)) ++b;
  while (b > 0 && speed < band_start(p, b) * (1.0f - p.hysteresis)) --b;
  return GaitBand(b);
}

GaitState entered(GaitState state, GaitPhase phase) {
  if (state.phase != phase) state.phase_seconds = 0.0f;
  state.phase = phase;
  return state;
}

}  // namespace

GaitOptions gait_options(const GaitCoverage& coverage) {
  GaitOptions options;
  for (std::size_t b = 0; b < kGaitBandCount; ++b) options.band[b] = coverage.band_frames[b] > 0;
  options.idle = coverage.can_stand();
  return options;
}

GaitState first_gait_state(const GaitBandParams& params, float commanded_speed) {
  GaitState state;
  state.band = gait_band_of_speed(params, commanded_speed);
  state.phase = state.band == GaitBand::Stand ? GaitPhase::Stand : GaitPhase::Move;
  return state;
}

GaitState next_gait_state(const GaitBandParams& params, const GaitState& state, float commanded_speed,
                          float simulated_speed, float dt) {
  GaitState next = state;
  next.phase_seconds += dt;
  next.band = banded(params, state.band, commanded_speed);
  const bool at_rest = simulated_speed < params.walk_from_mps;
  if (next.band == GaitBand::Stand) return entered(next, at_rest ? GaitPhase::Stand : GaitPhase::Stop);
  switch (state.phase) {
    case GaitPhase::Stand: return entered(next, GaitPhase::Start);
    case GaitPhase::Start: {
      const bool started = next.phase_seconds >= params.transition_seconds ||
                           simulated_speed >= 0.9f * commanded_speed;
      return started ? entered(next, GaitPhase::Move) : next;
    }
    case GaitPhase::Move:
    case GaitPhase::Stop: return entered(next, GaitPhase::Move);
  }
  return next;
}

GaitConstraint gait_constraint(const GaitState& state, const GaitOptions& options, const GaitTagBits& bits) {
  GaitConstraint c;
  const TagMask stand = bits.bit[std::size_t(GaitBand::Stand)];
  const TagMask stop = bits.bit[kGaitStopTag];
  switch (state.phase) {
    case GaitPhase::Stand:
      if (options.idle) {
        c.require_all = stand;
      } else {
        c.rest = true;
      }
      return c;
    case GaitPhase::Stop: return c;
    case GaitPhase::Start: c.exclude_any = stand | stop; return c;
    case GaitPhase::Move: break;
  }
  // The commanded band and its moving neighbours.
  const auto band = std::size_t(state.band);
  const std::size_t low = std::max<std::size_t>(band - 1, std::size_t(GaitBand::Walk));
  const std::size_t high = std::min(band + 1, kGaitBandCount - 1);
  TagMask excluded = stand | stop;
  bool any = false;
  for (std::size_t b = std::size_t(GaitBand::Walk); b < kGaitBandCount; ++b) {
    if (b >= low && b <= high) {
      any = any || options.band[b];
    } else {
      excluded |= bits.bit[b];
    }
  }
  c.exclude_any = any ? excluded : stand | stop;
  return c;
}

}  // namespace mmvk
