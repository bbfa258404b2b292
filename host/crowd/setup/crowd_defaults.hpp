// The controller settings the crowd runs with unless a setting
// (crowd_settings.hpp) or the data's "crowd" block (data_settings.hpp) says
// otherwise, shared by `mmvk crowd`, the stepped crowd and mmvk.Crowd, with
// the measurements that chose them.
#pragma once

#include <cstdint>

namespace mmvk::crowd {

// Characters in a random scenario when neither --agents nor a scenario says.
inline constexpr std::uint32_t kDefaultAgents = 1000;

// Added to the cost of the frame a character would play anyway: a jump must
// win by this much. Queries measure the pose the character shows, which
// (blended) lies further from every stored row than the row of the frame
// it plays did, so the bias that holds jumps to the same rate is larger.
// Measured with clusters, 200 characters, 10 s, seed 1, 30 Hz (trajectory
// error at 1 s, foot sliding before IK, transitions per character per s):
//   CMU 131:  -1: 0.046 m, 19.3 cm/s, 1.70;  -2: 0.050 m, 19.5, 1.27;  -3: 0.051 m, 20.2, 1.09
//   Bandai:   -1: 0.042 m, 24.9 cm/s, 2.50;  -2: 0.045 m, 24.8, 1.90
// (queries copied from the played frame's row, bias -1: CMU 0.055 m, 18.5,
// 1.32; Bandai 0.045 m, 25.8, 2.05). With foot IK and 1,000 characters for
// 20 s, Bandai jumped 2.04 times a second at -2, 1.86 at -2.5 and 1.74 at
// -3, following its paths 0.046, 0.047 and 0.048 m off (CMU: 1.30, 1.23,
// 1.17; 0.049, 0.050, 0.050 m). Feature costs are sums of squared z-scores,
// so the scale carries over to other databases.
inline constexpr float kContinuingBias = -2.5f;

// The root correction's half-life (ControllerParams::correction_half_life,
// 0.2 s by default). Foot locking holds planted feet against the correction,
// so the crowd can pull characters onto their paths harder than the
// animation alone could hide. 1,000 characters x 20 s (trajectory error at
// 1 s, sliding after IK, transitions per second):
//   CMU 131, 60 Hz:  0.2 s: 0.051 m, 0.38 cm/s, 1.23;  0.15 s: 0.042, 0.34, 1.18;  0.1 s: 0.031, 0.31, 1.11
//   Bandai, 60 Hz:   0.2 s: 0.048 m, 0.95 cm/s, 1.93;  0.15 s: 0.043, 0.89, 1.88;  0.1 s: 0.036, 0.87, 1.87
// 0.1 s clamps the legs' reach more often (7.1% of foot-ticks on CMU against
// 5.4%), so 0.15 s, for data of the user's; a shipped set carries its own
// (its manifest's "crowd" block).
inline constexpr float kCorrectionHalfLife = 0.15f;

}  // namespace mmvk::crowd
