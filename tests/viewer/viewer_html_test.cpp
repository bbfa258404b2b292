// The crowd viewer's page writer without a browser: recordings are checked
// field by field, the page is complete and self-contained, writes are atomic,
// and the page stays small at 1,000 characters x 20 s.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "support/test_data.hpp"
#include "viewer/recording_check.hpp"
#include "viewer/synthetic_recording.hpp"
#include "viewer/viewer_html.hpp"
#include "viewer/viewer_payload.hpp"

namespace mmvk::crowd {
namespace {

Recording small_recording() {
  SyntheticRecordingParams params;
  params.agents = 7;
  params.seconds = 3.0f;
  return make_synthetic_recording(params);
}

void expect_error(const Recording& r, const std::string& needle) {
  const Status status = validate_recording(r);
  ASSERT_FALSE(status.ok()) << "expected an error naming " << needle;
  EXPECT_NE(status.message().find(needle), std::string::npos) << status.message();
  const auto page = render_viewer_html(r);
  EXPECT_FALSE(page.ok()) << "render_viewer_html must refuse what validate_recording refuses";
}

TEST(ViewerRecording, SyntheticRecordingIsValid) {
  const Recording r = small_recording();
  EXPECT_EQ(r.agent_count, 7u);
  EXPECT_EQ(r.sample_count, 31u);  // 3 s at 10 Hz, both ends
  const Status status = validate_recording(r);
  EXPECT_TRUE(status.ok()) << status.message();
  for (const auto& searches : r.searches) EXPECT_GE(searches.size(), 25u);
}

TEST(ViewerRecording, ErrorsNameTheField) {
  Recording r = small_recording();
  r.root_x.pop_back();
  expect_error(r, "root_x");

  r = small_recording();
  r.sample_rate_hz = 0.0f;
  expect_error(r, "sample_rate_hz");

  r = small_recording();
  r.sample_count = 0;
  expect_error(r, "sample_count");

  r = small_recording();
  r.desired_z.resize(3);
  expect_error(r, "desired_z");

  r = small_recording();
  r.matched_x.clear();  // matched_z still full: both or neither
  expect_error(r, "matched_x");

  r = small_recording();
  r.trajectory_times_s = {0.5f, 0.5f, 1.0f};
  expect_error(r, "trajectory_times_s[1]");

  r = small_recording();
  r.joint_parents[3] = 5;
  expect_error(r, "joint_parents[3]");

  r = small_recording();
  std::swap(r.pose_frames[0], r.pose_frames[1]);
  expect_error(r, "pose_frames[1]");

  r = small_recording();
  r.pose_positions.pop_back();
  expect_error(r, "pose_positions");

  r = small_recording();
  r.searches[2][4].time_s = 0.0f;
  expect_error(r, "searches[2][4]");

  r = small_recording();
  r.goals.pop_back();
  expect_error(r, "goals");

  r = small_recording();
  r.facing[5] = std::nanf("");
  expect_error(r, "facing[5]");
}

TEST(ViewerRecording, WholePoseAndExplanationErrorsNameTheField) {
  Recording r = small_recording();
  ASSERT_FALSE(r.detail_agents.empty());
  r.detail_positions.pop_back();
  expect_error(r, "detail_positions");

  r = small_recording();
  r.detail_agents.back() = std::uint32_t(r.agent_count);
  expect_error(r, "detail_agents[6] = 7 is not below agent_count");

  // Any set, but ascending and unique: each slot's poses are one character's.
  r = small_recording();
  std::swap(r.detail_agents[1], r.detail_agents[2]);
  expect_error(r, "detail_agents[2] = 1 does not follow 2");

  r = small_recording();
  r.detail_agents[3] = r.detail_agents[2];
  expect_error(r, "detail_agents[3]");

  r = small_recording();
  r.detail_positions[10] = std::nanf("");
  expect_error(r, "detail_positions[10]");

  r = small_recording();
  r.why[1][3].chosen.clip = 9;
  expect_error(r, "why[1][3].chosen.clip");

  r = small_recording();
  r.why[1][3].continuing.weighted.pop_back();
  expect_error(r, "why[1][3].continuing.weighted");

  r = small_recording();
  r.why[2][1].search = r.why[2][0].search;
  expect_error(r, "why[2][1].search");

  r = small_recording();
  r.why[0][0].continuing.exclusion = 7;
  expect_error(r, "why[0][0].continuing.exclusion");

  r = small_recording();
  r.why.pop_back();
  expect_error(r, "why");
}

TEST(ViewerPage, IsSelfContained) {
  Recording r = small_recording();
  r.title = "a </script> title";
  const auto page = render_viewer_html(r);
  ASSERT_TRUE(page.ok()) << page.message();
  const std::string& html = page->html;
  EXPECT_EQ(html.find("@MMVK_"), std::string::npos) << "a placeholder was left in the page";
  // The only "</script" are the page's own six closing tags (the meta, the
  // data, three.js, viewer3d.js, viewer_why.js, viewer.js): the title
  // cannot end a script block early.
  std::size_t closings = 0;
  for (std::size_t at = html.find("</script"); at != std::string::npos; at = html.find("</script", at + 1)) ++closings;
  EXPECT_EQ(closings, 6u);
  EXPECT_NE(html.find("a \\u003c/script> title"), std::string::npos);
  // No network: nothing is fetched from elsewhere. three.js, the block after
  // the data, names two URLs it never fetches (the XHTML namespace and a
  // paper it cites) and has an image loader the page never calls; the rest
  // of the page names none.
  const std::size_t three_at = html.find("<script>", html.find("id=\"mmvk-data\""));
  const std::size_t three_end = html.find("</script>", three_at);
  ASSERT_NE(three_end, std::string::npos);
  const std::string three = html.substr(three_at, three_end - three_at);
  EXPECT_NE(three.find("THREE"), std::string::npos) << "the block after the data is not three.js";
  const std::string rest = html.substr(0, three_at) + html.substr(three_end);
  EXPECT_EQ(rest.find("http://"), std::string::npos);
  EXPECT_EQ(rest.find("https://"), std::string::npos);
  EXPECT_EQ(rest.find("src="), std::string::npos);
  std::size_t urls = 0;
  for (std::size_t at = three.find("http"); at != std::string::npos; at = three.find("http", at + 1)) {
    const std::string url = three.substr(at, 32);
    if (url.starts_with("http://") || url.starts_with("https://")) {
      ++urls;
      EXPECT_TRUE(url.starts_with("http://www.w3.org/1999/xhtml") || url.starts_with("https://graphics.stanford.edu/"))
          << url;
    }
  }
  EXPECT_EQ(urls, 5u);
  EXPECT_NE(html.find("\"agent_count\":7"), std::string::npos);
}

TEST(ViewerPage, EmptyCrowdStillMakesAPage) {
  Recording r;
  r.title = "nobody";
  const auto page = render_viewer_html(r);
  ASSERT_TRUE(page.ok()) << page.message();
  EXPECT_NE(page->html.find("\"agent_count\":0"), std::string::npos);
}

TEST(ViewerPage, PosesOnlyForPlayedFrames) {
  Recording r = small_recording();
  // Add a pose for a frame nobody plays: the page must not carry it.
  r.pose_frames.push_back(100000);
  r.pose_positions.resize(r.pose_positions.size() + r.joint_count() * 3, 0.5f);
  const auto payload = encode_viewer_payload(r);
  ASSERT_TRUE(payload.ok()) << payload.message();
  std::set<int32_t> played(r.frame.begin(), r.frame.end());
  EXPECT_NE(payload->meta_json.find("\"pose_count\":" + std::to_string(played.size())), std::string::npos)
      << payload->meta_json.substr(0, 400);
}

TEST(ViewerPage, WritesAtomicallyAndReportsBadPaths) {
  const auto dir = test::make_temp_dir();
  const Recording r = small_recording();
  const auto size = write_viewer_html(dir / "crowd.html", r);
  ASSERT_TRUE(size.ok()) << size.message();
  EXPECT_EQ(std::filesystem::file_size(dir / "crowd.html"), *size);
  // Only the page is left: the temporary file was renamed, not copied.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);

  const auto missing = write_viewer_html(dir / "no-such-folder" / "crowd.html", r);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("no-such-folder"), std::string::npos) << missing.message();
}

// The scale: the page must stay usable (and small) at 1,000
// characters x 20 s. The bound is about twice the measured size, so a
// change that undoes the quantization or the deflate fails here.
TEST(ViewerPage, ThousandAgentsForTwentySecondsStaysSmall) {
  SyntheticRecordingParams params;
  params.agents = 1000;
  params.seconds = 20.0f;
  const Recording r = make_synthetic_recording(params);
  const auto page = render_viewer_html(r);
  ASSERT_TRUE(page.ok()) << page.message();
  std::cout << "[ viewer ] 1000 agents x 20 s at " << r.sample_rate_hz << " Hz: page " << page->html.size()
            << " bytes (payload " << page->payload_raw_bytes << " raw, " << page->payload_compressed_bytes
            << " deflated)\n";
  EXPECT_LT(page->html.size(), std::size_t{8} << 20);
}

}  // namespace
}  // namespace mmvk::crowd
