// The recording as the page embeds it: a small JSON header (names, counts,
// section sizes) and one binary blob of zigzag varints, deflated.
//
// Why this form: 1,000 characters x 20 s at 10 Hz is 200,000 agent samples;
// as float32 with trajectories that is ~25 MB of base64. Positions are
// quantized (1 cm; facings 1/4096 turn; joints 1 mm; costs 1/1000; times
// 1 ms) and delta-coded along time, so most values fit in one byte, and
// deflate (which browsers undo with DecompressionStream) halves the rest.
// The page's decoder (viewer.js, decodePayload) reads the sections in the
// order and layout documented in viewer_payload.cpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mmvk/common/status.hpp"
#include "output/recording.hpp"

namespace mmvk::crowd {

struct ViewerPayload {
  std::string meta_json;            // UTF-8 JSON, '<' escaped so it can sit in a <script>
  std::vector<uint8_t> raw;         // the varint sections, concatenated
  std::vector<uint8_t> compressed;  // zlib (RFC 1950) deflate of raw
};

// Precondition: validate_recording(recording) passed. Errors: deflate failed.
Result<ViewerPayload> encode_viewer_payload(const Recording& recording);

}  // namespace mmvk::crowd
