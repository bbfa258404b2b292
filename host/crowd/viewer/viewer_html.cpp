#include "viewer/viewer_html.hpp"

#include <algorithm>
#include <array>
#include <string_view>

#include "mmvk/common/file_io.hpp"
#include "mmvk_viewer_assets.hpp"  // generated from viewer.html, its scripts and three.js
#include "viewer/recording_check.hpp"
#include "viewer/viewer_payload.hpp"

namespace mmvk::crowd {
namespace {

std::string base64(const std::vector<uint8_t>& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint32_t{bytes[i]} << 16) | (uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const uint32_t v = (uint32_t{bytes[i]} << 16) | (two ? uint32_t{bytes[i + 1]} << 8 : 0u);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// Fills the template's placeholders, each of which must occur exactly once.
// Positions are found in the template itself, so substituted text (the
// script, the data) is never searched again.
template <std::size_t N>
Result<std::string> fill_template(std::string_view page,
                                  const std::array<std::pair<std::string_view, std::string_view>, N>& fills) {
  std::array<std::size_t, N> at{};
  for (std::size_t i = 0; i < fills.size(); ++i) {
    at[i] = page.find(fills[i].first);
    if (at[i] == std::string_view::npos || page.find(fills[i].first, at[i] + 1) != std::string_view::npos) {
      return make_error("viewer: the embedded viewer.html must hold " + std::string(fills[i].first) + " exactly once");
    }
  }
  std::array<std::size_t, N> order{};
  for (std::size_t i = 0; i < N; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return at[a] < at[b]; });
  std::string out;
  std::size_t cursor = 0;
  for (std::size_t i : order) {
    out.append(page.substr(cursor, at[i] - cursor));
    out.append(fills[i].second);
    cursor = at[i] + fills[i].first.size();
  }
  out.append(page.substr(cursor));
  return out;
}

}  // namespace

Result<ViewerPage> render_viewer_html(const Recording& recording) {
  MMVK_TRY(validate_recording(recording));
  MMVK_ASSIGN_OR_RETURN(ViewerPayload payload, encode_viewer_payload(recording));
  const std::string_view script(kViewerJs, sizeof(kViewerJs) - 1);
  const std::string_view view3d(kViewer3dJs, sizeof(kViewer3dJs) - 1);
  const std::string_view why(kViewerWhyJs, sizeof(kViewerWhyJs) - 1);
  const std::string_view three(kThreeJs, sizeof(kThreeJs) - 1);
  for (const auto& [name, text] : {std::pair{"viewer.js", script}, std::pair{"viewer3d.js", view3d},
                                   std::pair{"viewer_why.js", why}, std::pair{"three.js", three}}) {
    if (text.find("</script") != std::string_view::npos) {
      return make_error(std::string("viewer: the embedded ") + name + " must not contain \"</script\"");
    }
  }
  const std::string data = base64(payload.compressed);
  MMVK_ASSIGN_OR_RETURN(std::string html,
                        fill_template(std::string_view(kViewerHtml, sizeof(kViewerHtml) - 1),
                                      std::array<std::pair<std::string_view, std::string_view>, 6>{
                                          {{"/*@MMVK_THREE@*/", three},
                                           {"/*@MMVK_VIEW3D@*/", view3d},
                                           {"/*@MMVK_WHY@*/", why},
                                           {"/*@MMVK_SCRIPT@*/", script},
                                           {"@MMVK_META@", payload.meta_json},
                                           {"@MMVK_DATA@", data}}}));
  return ViewerPage{std::move(html), payload.raw.size(), payload.compressed.size()};
}

Result<std::size_t> write_viewer_html(const std::filesystem::path& path, const Recording& recording) {
  MMVK_ASSIGN_OR_RETURN(ViewerPage page, render_viewer_html(recording));
  if (Status written = write_file_atomically(path, page.html); !written) {
    return make_error("viewer: " + written.message());
  }
  return page.html.size();
}

}  // namespace mmvk::crowd
