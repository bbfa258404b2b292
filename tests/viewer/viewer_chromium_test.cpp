// The crowd viewer in a real browser: headless Chromium (Debian's `chromium`)
// loads a page written by write_viewer_html at the scale (1,000
// characters x 20 s), the page reports that it initialized without a script
// error, and a screenshot shows the crowd, the selected skeleton, both
// trajectories and the jumps on the timeline.
//
// Skipped when no chromium is installed, unless MMVK_REQUIRE_VIEWER=1 (CI
// sets it), which turns a missing browser into a failure.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "png/png_decode.hpp"
#include "support/test_data.hpp"
#include "viewer/synthetic_recording.hpp"
#include "viewer/viewer_html.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

std::optional<fs::path> find_chromium() {
  if (const char* path = std::getenv("MMVK_CHROMIUM"); path && *path) return fs::path(path);
  const char* env_path = std::getenv("PATH");
  std::stringstream dirs(env_path ? env_path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    for (const char* name : {"chromium", "chromium-browser"}) {
      const fs::path candidate = fs::path(dir) / name;
      if (!dir.empty() && fs::exists(candidate)) return candidate;
    }
  }
  return std::nullopt;
}

bool viewer_required() {
  const char* value = std::getenv("MMVK_REQUIRE_VIEWER");
  return value && std::string(value) == "1";
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Where the page is opened: paused at 4 s with agent 3 selected, so the
// screenshot is deterministic.
constexpr const char* kQuery = "?t=4&agent=3&paused=1";

class ViewerChromium : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("mmvk-viewer-chromium-" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    SyntheticRecordingParams params;
    params.agents = kAgents;
    params.seconds = 20.0f;
    recording_ = new Recording(make_synthetic_recording(params));
    const auto size = write_viewer_html(*dir_ / "crowd.html", *recording_);
    page_error_ = new std::string(size.ok() ? "" : size.message());
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete page_error_;
    delete recording_;
  }

  void SetUp() override {
    ASSERT_TRUE(page_error_->empty()) << *page_error_;
    chromium_ = find_chromium();
    if (!chromium_) {
      if (viewer_required()) FAIL() << "chromium not found on PATH, and MMVK_REQUIRE_VIEWER=1 (apt-get install chromium)";
      GTEST_SKIP() << "chromium not found (apt-get install chromium, or set MMVK_CHROMIUM)";
    }
  }

  // Runs headless Chromium on `page` with one mode flag (--dump-dom or
  // --screenshot=...); returns its stdout. The virtual time budget lets the
  // page's asynchronous decoding finish before the DOM or the pixels are
  // taken. `webgl`: with WebGL on SwiftShader, Chromium's software GL (the
  // 3D view), instead of no GPU at all.
  std::string run_chromium(const fs::path& page, const std::string& mode, const std::string& tag,
                           const std::string& query = kQuery, bool webgl = false) {
    const fs::path profile = *dir_ / ("profile-" + tag);
    fs::remove_all(profile);
    fs::create_directories(profile);
    const fs::path out = *dir_ / (tag + ".out"), err = *dir_ / (tag + ".err");
    const std::string command = "timeout 120 '" + chromium_->string() +
                                "' --headless --no-sandbox" +
                                (webgl ? " --use-angle=swiftshader --enable-unsafe-swiftshader --ignore-gpu-blocklist"
                                       : " --disable-gpu") +
                                " --disable-quic --no-first-run"
                                " --disable-background-networking --disable-component-update --disable-sync"
                                " --hide-scrollbars --window-size=1280,800 --virtual-time-budget=10000"
                                " --user-data-dir='" + profile.string() + "' " + mode + " 'file://" +
                                page.string() + query + "' >'" + out.string() + "' 2>'" + err.string() + "'";
    const int rc = std::system(command.c_str());
    EXPECT_EQ(rc, 0) << command << "\nstderr:\n" << read_text(err);
    return read_text(out);
  }

  static constexpr std::size_t kAgents = 1000;
  static fs::path* dir_;
  static std::string* page_error_;
  static Recording* recording_;
  std::optional<fs::path> chromium_;
};

fs::path* ViewerChromium::dir_ = nullptr;
std::string* ViewerChromium::page_error_ = nullptr;
Recording* ViewerChromium::recording_ = nullptr;

// The page sets data-state="ready" on #status after its first full draw, and
// "error" (with the message) on any uncaught error or rejected promise.
std::string status_of(const std::string& dom) {
  std::smatch match;
  static const std::regex status_div("<div id=\"status\"[^>]*>[^<]*");
  return std::regex_search(dom, match, status_div) ? match.str() : "(no #status in the DOM)";
}

TEST_F(ViewerChromium, PageInitializesWithoutScriptError) {
  const std::string status = status_of(run_chromium(*dir_ / "crowd.html", "--dump-dom", "dom"));
  EXPECT_NE(status.find("data-state=\"ready\""), std::string::npos) << status;
  EXPECT_NE(status.find("data-drawn=\"" + std::to_string(kAgents) + "\""), std::string::npos) << status;
  std::cout << "[ viewer ] " << status << "\n";
}

// The page's decoder against the recording: what the page says it decoded
// for the selected character (agent 3 at 4 s, sample 40; see probe() in
// viewer.js) equals the recording within the quantization (1 cm, 1/4096
// turn, 1 mm, 1/1000 of cost).
TEST_F(ViewerChromium, PageDecodesWhatWasRecorded) {
  const std::string status = status_of(run_chromium(*dir_ / "crowd.html", "--dump-dom", "probe"));
  std::smatch match;
  static const std::regex probe_attribute("data-probe=\"([^\"]*)\"");
  ASSERT_TRUE(std::regex_search(status, match, probe_attribute)) << status;
  std::vector<double> v;
  std::stringstream fields(match[1].str());
  for (std::string field; std::getline(fields, field, ',');) v.push_back(std::stod(field));
  ASSERT_EQ(v.size(), 18u) << match[1].str();

  const Recording& r = *recording_;
  const std::size_t a = 3, s = 40, i = r.sample_index(s, a), k = r.trajectory_index(s, a, r.trajectory_points() - 1);
  EXPECT_EQ(v[0], double(a));
  EXPECT_EQ(v[1], double(s));
  EXPECT_NEAR(v[2], r.root_x[i], 0.0051);
  EXPECT_NEAR(v[3], r.root_z[i], 0.0051);
  const double turn = 2.0 * std::numbers::pi;
  EXPECT_NEAR(std::remainder(v[4] - r.facing[i], turn), 0.0, turn / 4096.0);
  EXPECT_EQ(v[5], double(r.frame[i]));
  EXPECT_NEAR(v[6], r.desired_x[k], 0.0051);
  EXPECT_NEAR(v[7], r.desired_z[k], 0.0051);
  EXPECT_NEAR(v[8], r.matched_x[k], 0.0051);
  EXPECT_NEAR(v[9], r.matched_z[k], 0.0051);
  const SearchEvent& last = r.searches[a].back();
  EXPECT_EQ(v[10], double(r.searches[a].size()));
  EXPECT_EQ(v[11], double(last.from_frame));
  EXPECT_EQ(v[12], double(last.to_frame));
  EXPECT_NEAR(v[13], last.cost, 0.00051);
  EXPECT_EQ(v[14], double(r.goals[a].size()));
  const auto pose = std::lower_bound(r.pose_frames.begin(), r.pose_frames.end(), r.frame[i]) - r.pose_frames.begin();
  EXPECT_NEAR(v[15], r.pose_positions[r.pose_index(std::size_t(pose), r.joint_count() - 1) + 1], 0.00051);
  // The last leg joint's height as displayed: the frame's joint to the
  // millimetre and the correction to 2 mm.
  EXPECT_NEAR(v[16], r.leg_positions[r.leg_index(s, a, r.leg_joints.size() - 1) + 1], 0.0016);
  EXPECT_EQ(v[17], double(r.foot_events[a].size()));
}

// A negative control: the same page with its data corrupted must say so,
// which shows the ready marker above is not set regardless.
TEST_F(ViewerChromium, CorruptDataIsReportedAsAnError) {
  std::string html = read_text(*dir_ / "crowd.html");
  const std::size_t data = html.find("id=\"mmvk-data\">");
  ASSERT_NE(data, std::string::npos);
  html.replace(data + 15, 64, std::string(64, 'A'));
  const fs::path broken = *dir_ / "broken.html";
  std::ofstream(broken) << html;
  const std::string status = status_of(run_chromium(broken, "--dump-dom", "broken"));
  EXPECT_NE(status.find("data-state=\"error\""), std::string::npos) << status;
}

// Issue 23: a tiny zoom (from the URL; the wheel goes through the same
// clamp) looped for ever drawing the grid, and thousands of goals per agent
// stalled every frame. The page must still report ready, with the view
// clamped and only visible goal segments drawn.
TEST_F(ViewerChromium, TinyZoomAndThousandsOfGoalsStayResponsive) {
  SyntheticRecordingParams params;
  params.agents = 100;
  params.seconds = 10.0f;
  Recording r = make_synthetic_recording(params);
  for (std::size_t a = 0; a < r.goals.size(); ++a) {
    r.goals[a].clear();
    for (int g = 0; g < 5000; ++g) {
      r.goals[a].push_back({float((g * 7 + int(a)) % 200) - 100.0f, float((g * 13 + int(a) * 3) % 200) - 100.0f});
    }
  }
  const auto size = write_viewer_html(*dir_ / "goals.html", r);
  ASSERT_TRUE(size.ok()) << size.message();
  for (const char* zoom : {"1e-300", "1e-9", "1e300", "0.5"}) {
    const std::string status = status_of(run_chromium(*dir_ / "goals.html", "--dump-dom", std::string("zoom") + zoom,
                                                      std::string("?t=4&agent=3&paused=1&zoom=") + zoom));
    EXPECT_NE(status.find("data-state=\"ready\""), std::string::npos) << "zoom=" << zoom << ": " << status;
  }
}

// Issue 34: one character with 20,000 goals took 3-63 s (and more than
// 100 s in three runs of six) to open: every frame drew the selected
// character's whole goal path dashed (hundreds of thousands of dashes), a
// disc per goal, and everyone's goal paths again. Playing (a frame per
// animation frame for the 10 s of virtual time), the page must open and
// report ready. The target is 5 s of wall time; on a shared,
// loaded machine the same run of a 4-goal page varies from 2 to 20 s, so
// the bound here is what tells the fixed page (a cached ground layer) from
// the old one, whose runs went past 100 s.
TEST_F(ViewerChromium, TwentyThousandGoalsOpenWithoutStalling) {
  SyntheticRecordingParams params;
  params.agents = 1;
  params.seconds = 10.0f;
  Recording r = make_synthetic_recording(params);
  r.goals[0].clear();
  for (int g = 0; g < 20000; ++g) {
    r.goals[0].push_back({float((g * 7919) % 600) / 10.0f - 30.0f, float((g * 104729) % 600) / 10.0f - 30.0f});
  }
  const auto size = write_viewer_html(*dir_ / "goals20k.html", r);
  ASSERT_TRUE(size.ok()) << size.message();
  const auto start = std::chrono::steady_clock::now();
  const std::string status = status_of(run_chromium(*dir_ / "goals20k.html", "--dump-dom", "goals20k", "?agent=0"));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(status.find("data-state=\"ready\""), std::string::npos) << status;
  std::cout << "[ viewer ] 20,000 goals: opened and played 10 s (virtual) in " << seconds << " s\n";
  EXPECT_LT(seconds, 60.0);
}

struct Rgb {
  int r, g, b;
};

// Pixels in [x0, x1) x [y0, y1) that pass `keep`.
template <class Keep>
std::size_t count_pixels(const test::RgbImage& image, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1, Keep keep) {
  std::size_t count = 0;
  for (uint32_t y = y0; y < std::min(y1, image.height); ++y) {
    for (uint32_t x = x0; x < std::min(x1, image.width); ++x) {
      const uint8_t* p = image.pixel(x, y);
      if (keep(Rgb{p[0], p[1], p[2]})) ++count;
    }
  }
  return count;
}

bool near(Rgb p, Rgb target) {
  return std::abs(p.r - target.r) + std::abs(p.g - target.g) + std::abs(p.b - target.b) < 60;
}

// The regions follow viewer.html's grid at 1280 x 800: the crowd on the left,
// the skeleton and the trajectory stacked on the right, the timeline below;
// each region skips its panel's text label.
TEST_F(ViewerChromium, ScreenshotShowsCrowdSkeletonTrajectoriesAndTimeline) {
  const fs::path png = *dir_ / "crowd.png";
  run_chromium(*dir_ / "crowd.html", "--screenshot=" + png.string(), "shot");
  const auto image = test::read_png(png);
  ASSERT_TRUE(image.ok()) << image.message();
  ASSERT_EQ(image->width, 1280u);
  ASSERT_EQ(image->height, 800u);

  // Characters are discs in saturated hues; the ground, grid and goal paths
  // are grey.
  const std::size_t characters = count_pixels(*image, 10, 80, 820, 610, [](Rgb p) {
    return std::max({p.r, p.g, p.b}) - std::min({p.r, p.g, p.b}) >= 80;
  });
  // Bones: left cyan, right pink, centre near white.
  const std::size_t bones = count_pixels(*image, 840, 80, 1270, 340, [](Rgb p) {
    return near(p, {0x5e, 0xc8, 0xff}) || near(p, {0xff, 0x8f, 0xb1}) || near(p, {0xe8, 0xec, 0xf2});
  });
  const std::size_t desired = count_pixels(*image, 840, 375, 1270, 615, [](Rgb p) { return near(p, {0xff, 0xa2, 0x3a}); });
  const std::size_t achieved = count_pixels(*image, 840, 375, 1270, 615, [](Rgb p) { return near(p, {0x39, 0xc6, 0xf0}); });
  const std::size_t jumps = count_pixels(*image, 40, 665, 1270, 780, [](Rgb p) { return near(p, {0xff, 0x6b, 0x5a}); });
  std::cout << "[ viewer ] screenshot pixels: characters " << characters << ", bones " << bones << ", desired "
            << desired << ", achieved " << achieved << ", jumps " << jumps << "\n";
  // Each character covers ~20 pixels at this zoom; a quarter of that for
  // every character is the floor.
  EXPECT_GE(characters, kAgents * 5);
  EXPECT_GE(bones, 300u);
  EXPECT_GE(desired, 100u);
  EXPECT_GE(achieved, 100u);
  EXPECT_GE(jumps, 30u);
}

// Zoomed on a walking character's feet while one is locked: the crowd view
// marks each locked foot on the ground (green), and so does the skeleton.
TEST_F(ViewerChromium, ZoomedOnTheFeetShowsWhereTheyAreLocked) {
  const Recording& r = *recording_;
  // The first agent with a foot locked at a sample after 2 s.
  std::size_t agent = r.agent_count;
  float at = 0.0f;
  for (std::size_t a = 0; a < r.agent_count && agent == r.agent_count; ++a) {
    for (const FootEvent& event : r.foot_events[a]) {
      if (event.time_s >= 2.0f && (event.state & (kFootLockedLeft | kFootLockedRight))) {
        agent = a, at = event.time_s;
        break;
      }
    }
  }
  ASSERT_LT(agent, r.agent_count) << "the synthetic crowd locks no foot";
  const fs::path png = *dir_ / "feet.png";
  const std::string query =
      "?t=" + std::to_string(at) + "&agent=" + std::to_string(agent) + "&paused=1&zoom=400&follow=1";
  run_chromium(*dir_ / "crowd.html", "--screenshot=" + png.string(), "feet", query);
  const auto image = test::read_png(png);
  ASSERT_TRUE(image.ok()) << image.message();
  const auto locked = [](Rgb p) { return near(p, {0x7d, 0xff, 0x8a}); };
  const std::size_t crowd = count_pixels(*image, 10, 80, 820, 610, locked);
  const std::size_t skeleton = count_pixels(*image, 840, 80, 1270, 340, locked);
  const std::size_t timeline = count_pixels(*image, 40, 640, 1270, 780, locked);
  std::cout << "[ viewer ] agent " << agent << " at " << at << " s, locked-foot pixels: crowd " << crowd
            << ", skeleton " << skeleton << ", timeline " << timeline << "\n";
  // A marker is a disc or square of 0.045 m at 400 px/m (18 px across).
  EXPECT_GE(crowd, 150u);
  EXPECT_GE(skeleton, 25u);
  EXPECT_GE(timeline, 100u);
}

// The numbers a status attribute holds, comma-separated ("" when absent).
std::vector<double> status_numbers(const std::string& status, const std::string& attribute) {
  std::smatch match;
  const std::regex pattern(attribute + "=\"([^\"]*)\"");
  std::vector<double> v;
  if (!std::regex_search(status, match, pattern)) return v;
  std::stringstream fields(match[1].str());
  for (std::string field; std::getline(fields, field, ',');) v.push_back(std::stod(field));
  return v;
}

// The 3D view (viewer3d.js: three.js on WebGL): around the selected
// character's hips, the page differs from the same view of the empty ground
// (?characters=0), and the ground itself was drawn (not the clear colour).
TEST_F(ViewerChromium, ThreeDViewShowsCharactersWhereTheyStand) {
  SyntheticRecordingParams params;
  params.agents = 40;
  params.seconds = 6.0f;
  const fs::path page = *dir_ / "small.html";
  ASSERT_TRUE(write_viewer_html(page, make_synthetic_recording(params)).ok());
  const std::string query = "?t=3&agent=3&paused=1&view=3d&cam=5,0.6,0.3";
  const std::string status = status_of(run_chromium(page, "--dump-dom", "3d-dom", query, true));
  ASSERT_NE(status.find("data-state=\"ready\""), std::string::npos) << status;
  EXPECT_NE(status.find("data-view=\"3d\""), std::string::npos) << status;
  const std::vector<double> at = status_numbers(status, "data-projected");
  ASSERT_EQ(at.size(), 2u) << status;
  const fs::path with = *dir_ / "3d.png", without = *dir_ / "3d-empty.png";
  run_chromium(page, "--screenshot=" + with.string(), "3d", query, true);
  run_chromium(page, "--screenshot=" + without.string(), "3d-empty", query + "&characters=0", true);
  const auto a = test::read_png(with), b = test::read_png(without);
  ASSERT_TRUE(a.ok() && b.ok()) << a.message() << b.message();
  ASSERT_EQ(a->width, b->width);
  ASSERT_EQ(a->height, b->height);
  const auto x = std::uint32_t(std::lround(at[0])), y = std::uint32_t(std::lround(at[1]));
  ASSERT_TRUE(x >= 8 && y >= 8 && x + 8 < a->width && y + 8 < a->height) << x << "," << y;
  std::size_t differ = 0;
  for (std::uint32_t py = y - 8; py <= y + 8; ++py) {
    for (std::uint32_t px = x - 8; px <= x + 8; ++px) {
      const uint8_t *p = a->pixel(px, py), *q = b->pixel(px, py);
      differ += std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 40;
    }
  }
  // The empty ground: drawn by WebGL, so not the page's clear colour.
  const std::size_t ground = count_pixels(*b, 10, 80, 820, 610, [](Rgb p) { return !near(p, {0x14, 0x17, 0x1c}); });
  std::cout << "[ viewer ] 3D: hips at " << x << "," << y << ", " << differ << " of 289 pixels around them differ "
            << "from the empty ground; " << ground << " ground pixels\n";
  EXPECT_GE(differ, 72u);
  EXPECT_GE(ground, 810u * 530u / 3);
}

// Why this frame: a search opened from the URL (as a click on the timeline
// opens it) shows the recorded explanation, within its quantization
// (frames exact, costs to 1e-5 each); a character whose searches are not
// explained opens none.
TEST_F(ViewerChromium, WhyPanelShowsTheRecordedExplanation) {
  const Recording& r = *recording_;
  ASSERT_GT(r.detail_agents.size(), 3u);
  ASSERT_EQ(r.detail_agents[3], 3u);
  const Recording::SearchWhy& why = r.why[3][7];
  ASSERT_EQ(why.search, 7u);
  const std::vector<double> v =
      status_numbers(status_of(run_chromium(*dir_ / "crowd.html", "--dump-dom", "why", "?t=4&agent=3&paused=1&why=7")),
                     "data-why");
  ASSERT_EQ(v.size(), 5u);
  EXPECT_EQ(v[0], double(why.chosen.frame));
  EXPECT_EQ(v[1], double(why.continuing.frame));
  EXPECT_NEAR(v[2], why.chosen.cost, 1e-5);
  EXPECT_NEAR(v[3], why.continuing.cost, 1e-5);
  double sum = 0.0;
  for (float c : why.chosen.weighted) sum += c;
  EXPECT_NEAR(v[4], sum, 1e-5 * double(why.chosen.weighted.size()));
  const std::string none = status_of(run_chromium(*dir_ / "crowd.html", "--dump-dom", "why-none",
                                                  "?t=4&agent=" + std::to_string(r.detail_agents.size()) + "&paused=1&why=2"));
  EXPECT_NE(none.find("data-why=\"\""), std::string::npos) << none;
}

// Any set of characters in detail (`mmvk crowd --detail-agents 2-3,7`), not
// only the first: a detailed character is drawn with its whole pose at the
// tick rate (the recording's, to the millimetre of the payload) and its
// searches are explained; one between them (5) or before them (0) falls
// back to its played frame at the 10 Hz samples, and its panel names the set.
TEST_F(ViewerChromium, AnySetOfDetailedCharactersIsDrawnAndExplained) {
  SyntheticRecordingParams params;
  params.agents = 12;
  params.seconds = 6.0f;
  params.detail_set = {2, 3, 7};
  const Recording r = make_synthetic_recording(params);
  const fs::path page = *dir_ / "detail-set.html";
  ASSERT_TRUE(write_viewer_html(page, r).ok());
  const std::size_t joints = r.joint_count(), tick = 120;  // t = 4 s at 30 Hz
  ASSERT_LT(tick, r.detail_sample_count);

  const std::string detailed = status_of(run_chromium(page, "--dump-dom", "set-7", "?t=4&agent=7&paused=1&why=5"));
  ASSERT_NE(detailed.find("data-state=\"ready\""), std::string::npos) << detailed;
  const std::vector<double> pose = status_numbers(detailed, "data-pose");
  ASSERT_EQ(pose.size(), 1 + joints * 3) << detailed;
  EXPECT_EQ(pose[0], 1.0) << "character 7 is detailed";
  for (std::size_t c = 0; c < joints * 3; ++c) {
    // Slot 2 is character 7; joint 0 in mm, the others in mm against it.
    EXPECT_NEAR(pose[1 + c], r.detail_positions[r.detail_index(tick, 2, 0) + c], 0.0021) << "coordinate " << c;
  }
  const std::vector<double> why = status_numbers(detailed, "data-why");
  ASSERT_EQ(why.size(), 5u) << detailed;
  EXPECT_EQ(why[0], double(r.why[7][5].chosen.frame));

  for (const std::size_t a : {std::size_t{5}, std::size_t{0}}) {
    const std::string dom =
        run_chromium(page, "--dump-dom", "set-" + std::to_string(a), "?t=4&agent=" + std::to_string(a) + "&paused=1&why=2");
    const std::string status = status_of(dom);
    ASSERT_NE(status.find("data-state=\"ready\""), std::string::npos) << status;
    const std::vector<double> shown = status_numbers(status, "data-pose");
    ASSERT_EQ(shown.size(), 1 + joints * 3) << status;
    EXPECT_EQ(shown[0], 0.0) << "character " << a << " is not detailed";
    // The played frame's pose (no lift of the synthetic whole poses): the
    // highest joint's height to the millimetre.
    const std::size_t i = r.sample_index(40, a);
    const auto slot = std::size_t(std::lower_bound(r.pose_frames.begin(), r.pose_frames.end(), r.frame[i]) -
                                  r.pose_frames.begin());
    std::size_t top = 0;
    for (std::size_t j = 0; j < joints; ++j) {
      if (r.pose_positions[r.pose_index(slot, j) + 1] > r.pose_positions[r.pose_index(slot, top) + 1]) top = j;
    }
    EXPECT_NEAR(shown[1 + 3 * top + 1], r.pose_positions[r.pose_index(slot, top) + 1], 0.0011) << "character " << a;
    EXPECT_NE(status.find("data-why=\"\""), std::string::npos) << status;
    EXPECT_NE(dom.find("explains the searches of 3 characters: 2-3, 7"), std::string::npos) << "character " << a;
  }
}

}  // namespace
}  // namespace mmvk::crowd
