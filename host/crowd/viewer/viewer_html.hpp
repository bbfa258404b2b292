// The crowd viewer: one self-contained HTML page (no network, no CDN) that
// replays a Recording: the crowd from above with a time slider, a selected
// character's skeleton, its desired against its achieved trajectory, and its
// searches and jumps on a timeline. The page's HTML and JavaScript live in
// viewer.html and viewer.js beside this file and are embedded at build time.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "mmvk/common/status.hpp"
#include "output/recording.hpp"

namespace mmvk::crowd {

struct ViewerPage {
  std::string html;
  std::size_t payload_raw_bytes = 0;         // the encoded recording before deflate
  std::size_t payload_compressed_bytes = 0;  // after deflate, before base64
};

// Builds the page in memory. Errors: an inconsistent recording (the field at
// fault is named; see validate_recording) or a compression failure.
Result<ViewerPage> render_viewer_html(const Recording& recording);

// Renders the page and writes it to `path` with mmvk's one writer
// (write_file_atomically): a regular file is replaced atomically, so a
// reader never sees half a page; a FIFO or device is written in place.
// Errors name the path and the failing step.
// Returns the size of the written file in bytes.
Result<std::size_t> write_viewer_html(const std::filesystem::path& path, const Recording& recording);

}  // namespace mmvk::crowd
