// The phase channel (features.hpp, docs/database.md "Phase"): per source
// curve and frame, the curve over a centred window with its mean removed,
// its spectrum by a zero-padded FFT, the strongest non-constant frequency,
// and that frequency's amplitude and phase at the window's centre, emitted
// as (a sin 2 pi phi, a cos 2 pi phi) so that the cyclic phase has no seam
// and a flat curve (a = 0) has none at all. Following the deterministic part
// of DeepPhase's frequency-domain parametrization (Starke et al. 2022), not
// its learned layers (learned phases come in as a sidecar, see docs).
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>

#include "features/channel_extraction.hpp"
#include "features/real_fft.hpp"
#include "mmvk/features/features.hpp"

namespace mmvk::detail {

namespace {

// Zero padding: a frequency grid four times finer than the window's own
// resolution (fps / window), so the dominant frequency moves smoothly.
constexpr std::size_t kPadding = 4;

double curve_value(const ChannelExtraction& job, const CurveSource& curve, std::uint32_t f) {
  switch (curve.kind) {
    case CurveSource::Kind::Speed:
      return glm::length(job.clip.bone_velocity(f, curve.joint));
    case CurveSource::Kind::Height:
      return job.clip.bone_position(f, curve.joint).y;
    case CurveSource::Kind::Column:
      return job.features[std::size_t{f} * job.stride + curve.column];
  }
  return 0.0;
}

}  // namespace

void extract_phase(const ChannelExtraction& job) {
  const ClipSamples& clip = job.clip;
  const std::uint32_t half = window_frames(job.channel.window_seconds, clip.motion.fps);
  const std::size_t samples = 2 * std::size_t{half} + 1;
  RealFft fft(next_power_of_two(kPadding * samples));
  const double padded = static_cast<double>(fft.size());
  std::vector<double> curve(clip.frames());
  std::vector<double> window(samples);
  std::vector<std::complex<double>> spectrum;
  for (std::size_t c = 0; c < job.curves.size(); ++c) {
    for (std::uint32_t f = 0; f < clip.frames(); ++f) curve[f] = curve_value(job, job.curves[c], f);
    for (std::uint32_t f = 0; f < clip.frames(); ++f) {
      double mean = 0.0;
      for (std::size_t m = 0; m < samples; ++m) {
        window[m] = curve[clip.window_frame(f, static_cast<std::int64_t>(m) - half)];
        mean += window[m];
      }
      mean /= static_cast<double>(samples);
      for (double& value : window) value -= mean;
      fft.forward(window, spectrum);
      // The strongest bin above 0 Hz; the lowest on a tie.
      std::size_t best = 0;
      double best_power = 0.0;
      for (std::size_t k = 1; k < spectrum.size(); ++k) {
        const double power = std::norm(spectrum[k]);
        if (power > best_power) {
          best_power = power;
          best = k;
        }
      }
      float* out = job.row(f) + 2 * c;
      if (best == 0) {  // a constant window: no oscillation, no phase
        out[0] = 0.0f;
        out[1] = 0.0f;
        continue;
      }
      // The bin with its time origin moved from the window's first sample to
      // its centre; for x(t) = a cos(2 pi (nu t + phi)) it is (a N / 2) e^(2 pi i phi).
      const double shift = 2.0 * std::numbers::pi * static_cast<double>(best) * half / padded;
      const std::complex<double> centred = spectrum[best] * std::polar(1.0, shift);
      const double scale = 2.0 / static_cast<double>(samples);
      out[0] = static_cast<float>(scale * centred.imag());  // a sin 2 pi phi
      out[1] = static_cast<float>(scale * centred.real());  // a cos 2 pi phi
    }
  }
}

}  // namespace mmvk::detail
