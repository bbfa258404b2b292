// The controller settings the crowd runs with unless a setting
// (crowd_settings.hpp) or the data's "crowd" block (data_settings.hpp) says
// otherwise, shared by `mmvk crowd`, the stepped crowd and mmvk.Crowd.
#pragma once

#include <cstdint>

namespace mmvk::crowd {

// Characters in a random scenario when neither --agents nor a scenario says.
inline constexpr std::uint32_t kDefaultAgents = 1000;

// Added to the cost of the frame a character would play anyway: a jump must
// win by this much. Queries measure the pose the character shows, which
// (blended) lies further from every stored row than the row of the frame
// it plays did, so the bias that holds jumps to the same rate is larger.
// Feature costs are sums of squared z-scores, so the scale carries over to
// other databases. The runs that chose it: bench/RESULTS.md, "Defaults and
// the measurements that chose them".
inline constexpr float kContinuingBias = -2.5f;

// The root correction's half-life (ControllerParams::correction_half_life,
// 0.2 s by default). Foot locking holds planted feet against the correction,
// so the crowd can pull characters onto their paths harder than the
// animation alone could hide; shorter still clamps the legs' reach more
// often. A shipped set carries its own (its manifest's "crowd" block). The
// runs that chose it: bench/RESULTS.md, "Defaults and the measurements that
// chose them".
inline constexpr float kCorrectionHalfLife = 0.15f;

}  // namespace mmvk::crowd
