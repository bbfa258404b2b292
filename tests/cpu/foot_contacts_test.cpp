// Foot contact detection on hand-placed feet with known answers: horizontal
// (not 3-D) speed, hysteresis, the minimum durations, toe and heel apart, the
// planted foot held across a short gap, a skeleton without toes (DAZ), the
// same labels at 30 and 120 fps; then the labels and their parameters in the
// .mmdb, and format 3 and 4 files with the old labels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "fuzz/repair_mmdb.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"

namespace mmvk {
namespace {

constexpr float kFps = 30.0f;

// Model-space positions of the four contact points, one per frame.
struct Feet {
  std::vector<glm::vec3> left_toe, left_heel, right_toe, right_heel;
  std::uint32_t frames() const { return static_cast<std::uint32_t>(left_toe.size()); }
};

// Feet standing still at the floor, `frames` long.
Feet standing(std::uint32_t frames) {
  Feet feet;
  feet.left_toe.assign(frames, glm::vec3(0.1f, 0.0f, 0.15f));
  feet.left_heel.assign(frames, glm::vec3(0.1f, 0.0f, 0.0f));
  feet.right_toe.assign(frames, glm::vec3(-0.1f, 0.0f, 0.15f));
  feet.right_heel.assign(frames, glm::vec3(-0.1f, 0.0f, 0.0f));
  return feet;
}

// A motion whose contact points sit exactly where `feet` says: every joint
// hangs straight off the still hips, so its local translation is its
// model-space offset from them. Bandai names (the roles resolve), or DAZ
// names without toes.
Motion motion_of(const Feet& feet, float fps, bool toes = true) {
  Motion m;
  const glm::vec3 hips(0.0f, 1.0f, 0.0f);
  if (toes) {
    m.skeleton.names = {"Hips", "UpperLeg_L", "UpperLeg_R", "Foot_L", "Toes_L", "Foot_R", "Toes_R"};
  } else {
    m.skeleton.names = {"hip", "lThigh", "rThigh", "lFoot", "rFoot"};
  }
  m.skeleton.parents.assign(m.skeleton.names.size(), 0);
  m.skeleton.parents[0] = -1;
  m.skeleton.rest_offsets = {hips, glm::vec3(0.1f, -0.05f, 0.0f), glm::vec3(-0.1f, -0.05f, 0.0f)};
  m.skeleton.rest_offsets.resize(m.skeleton.names.size(), glm::vec3(0.0f, -0.9f, 0.0f));
  m.fps = fps;
  m.frame_count = feet.frames();
  for (std::uint32_t f = 0; f < feet.frames(); ++f) {
    std::vector<glm::vec3> points = {hips, m.skeleton.rest_offsets[1], m.skeleton.rest_offsets[2]};
    if (toes) {
      for (const glm::vec3& p : {feet.left_heel[f], feet.left_toe[f], feet.right_heel[f], feet.right_toe[f]}) {
        points.push_back(p - hips);
      }
    } else {
      for (const glm::vec3& p : {feet.left_heel[f], feet.right_heel[f]}) points.push_back(p - hips);
    }
    m.local_positions.insert(m.local_positions.end(), points.begin(), points.end());
    m.local_rotations.insert(m.local_rotations.end(), points.size(), glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  }
  return m;
}

// The animation is what these tests read; the features are one custom
// channel that varies (a still foot would give the default schema's feet a
// zero spread, which normalization refuses).
Result<Database> build(const Feet& feet, const FootContactParams& params = {}, float fps = kFps, bool toes = true) {
  std::vector<MotionClip> clips(1);
  clips[0].meta.file = "feet.bvh";
  clips[0].meta.name = "feet";
  clips[0].motion = motion_of(feet, fps, toes);
  clips[0].custom.emplace_back();
  for (std::uint32_t f = 0; f < feet.frames(); ++f) clips[0].custom[0].push_back(float(f));
  MotionBuildSettings settings;
  Result<FeatureSchema> schema =
      parse_schema_json(R"({"channels": [{"name": "frame", "kind": "custom", "dims": 1}]})", "schema");
  EXPECT_TRUE(schema.ok()) << schema.message();
  if (schema.ok()) settings.schema = *schema;
  settings.contacts = params;
  return build_database_from_motions(clips, settings);
}

std::vector<std::uint8_t> contacts_of(const Feet& feet, const FootContactParams& params = {}, float fps = kFps,
                                      bool toes = true) {
  Result<Database> db = build(feet, params, fps, toes);
  EXPECT_TRUE(db.ok()) << db.message();
  if (!db.ok() || db->animation() == nullptr) return {};
  return db->animation()->contacts;
}

// The frames where `bit` is set, as "[a, b] [c, d]" runs, for readable failures.
std::string runs(const std::vector<std::uint8_t>& contacts, std::uint8_t bit) {
  std::string out;
  for (std::size_t f = 0; f < contacts.size(); ++f) {
    if (!(contacts[f] & bit) || (f > 0 && (contacts[f - 1] & bit))) continue;
    std::size_t end = f;
    while (end + 1 < contacts.size() && (contacts[end + 1] & bit)) ++end;
    out += (out.empty() ? "[" : " [") + std::to_string(f) + ", " + std::to_string(end) + "]";
  }
  return out;
}

// Moves the left foot (toe and heel together) by speed[f] m/s along +Z over
// the step from frame f to f + 1.
void slide_left(Feet& feet, const std::vector<float>& speed) {
  for (std::size_t f = 0; f + 1 < feet.left_toe.size(); ++f) {
    const glm::vec3 step(0.0f, 0.0f, speed[f] / kFps);
    for (std::vector<glm::vec3>* point : {&feet.left_toe, &feet.left_heel}) {
      for (std::size_t g = f + 1; g < point->size(); ++g) (*point)[g] += step;
    }
  }
}

TEST(FootContacts, HorizontalSpeedDecidesNotVertical) {
  Feet feet = standing(90);
  // The left foot bobs 1 cm up and down at 4 Hz (vertical speed up to
  // 0.13 m/s, past exit_speed) without moving horizontally; the right foot
  // slides along the floor at 0.3 m/s.
  for (std::uint32_t f = 0; f < 90; ++f) {
    const float t = float(f) / kFps;
    const float lift = 0.005f * (1.0f - std::cos(2.0f * std::numbers::pi_v<float> * 4.0f * t));
    feet.left_toe[f].y = feet.left_heel[f].y = lift;
    feet.right_toe[f].z += 0.3f * t;
    feet.right_heel[f].z += 0.3f * t;
  }
  float vertical = 0.0f;
  for (std::uint32_t f = 0; f + 1 < 90; ++f) {
    vertical = std::max(vertical, std::abs(feet.left_toe[f + 1].y - feet.left_toe[f].y) * kFps);
  }
  ASSERT_GT(vertical, FootContactParams{}.exit_speed)
      << "the fixture's vertical speed must exceed the thresholds for the test to mean anything";
  const std::vector<std::uint8_t> c = contacts_of(feet);
  ASSERT_EQ(c.size(), 90u);
  for (std::uint32_t f = 0; f < 90; ++f) {
    EXPECT_EQ(c[f], kContactLeft | kContactLeftToe | kContactLeftHeel) << "frame " << f;
  }
}

TEST(FootContacts, HysteresisOnSpeedAndHeight) {
  // Step speeds of the left foot: still, then 0.06 m/s (between enter 0.05
  // and exit 0.075: it stays planted), 0.1 (it lifts off), 0.06 again (too
  // fast to plant anew), still.
  std::vector<float> speed(60, 0.0f);
  for (std::size_t f = 10; f < 40; ++f) speed[f] = f < 20 || f >= 30 ? 0.06f : 0.1f;
  Feet feet = standing(60);
  slide_left(feet, speed);
  const std::uint8_t left = kContactLeft;
  EXPECT_EQ(runs(contacts_of(feet), left), "[0, 20] [40, 59]");
  // Without hysteresis one threshold decides both ways.
  FootContactParams loose;
  loose.enter_speed = loose.exit_speed = 0.075f;
  EXPECT_EQ(runs(contacts_of(feet, loose), left), "[0, 20] [30, 59]");
  FootContactParams strict;
  strict.enter_speed = strict.exit_speed = 0.05f;
  EXPECT_EQ(runs(contacts_of(feet, strict), left), "[0, 10] [40, 59]");

  // Height: a still foot raised 2.5 cm (between enter 0.02 and exit 0.03)
  // stays planted, lowered from 5 cm to 2.5 cm does not plant.
  Feet raised = standing(60);
  for (std::uint32_t f = 0; f < 60; ++f) {
    const float y = f < 10 ? 0.0f : f < 20 ? 0.025f : f < 30 ? 0.05f : f < 40 ? 0.025f : 0.0f;
    raised.left_toe[f].y = raised.left_heel[f].y = y;
  }
  // The floor is the 5th percentile of each joint's height: 0 here.
  EXPECT_EQ(runs(contacts_of(raised), left), "[0, 19] [40, 59]");
}

TEST(FootContacts, ShortContactsGoAndShortGapsClose) {
  // The left foot slides at 0.3 m/s but for one still step (a 2-frame
  // contact: removed) and two (3 frames: kept); the right foot stands but
  // for 2, 3 and 4 fast steps (gaps of 1 and 2 frames: closed; 3: kept).
  std::vector<float> speed(90, 0.3f);
  speed[20] = speed[40] = speed[41] = 0.0f;
  Feet feet = standing(90);
  slide_left(feet, speed);
  for (std::uint32_t f = 0; f < 90; ++f) {
    const auto fast_steps_before = [&](std::uint32_t g) {
      std::uint32_t n = 0;
      for (std::uint32_t s : {20u, 21u, 40u, 41u, 42u, 60u, 61u, 62u, 63u}) n += s < g ? 1 : 0;
      return n;
    };
    const float z = 0.3f / kFps * float(fast_steps_before(f));
    feet.right_toe[f].z += z;
    feet.right_heel[f].z += z;
  }
  const std::vector<std::uint8_t> c = contacts_of(feet);
  EXPECT_EQ(runs(c, kContactLeft), "[40, 42]");
  EXPECT_EQ(runs(c, kContactRight), "[0, 60] [64, 89]");
  // With no minimum durations every run stays.
  FootContactParams raw;
  raw.min_contact_seconds = raw.min_gap_seconds = 0.0f;
  const std::vector<std::uint8_t> r = contacts_of(feet, raw);
  EXPECT_EQ(runs(r, kContactLeft), "[20, 21] [40, 42]");
  EXPECT_EQ(runs(r, kContactRight), "[0, 20] [22, 40] [43, 60] [64, 89]");

  // A short contact at the clip's start is kept: its length is unknown.
  std::vector<float> start(60, 0.3f);
  start[0] = 0.0f;
  Feet edge = standing(60);
  slide_left(edge, start);
  EXPECT_EQ(runs(contacts_of(edge), kContactLeft), "[0, 1]");
}

// A foot that rolls: heel strike, flat, heel off, toe off.
Feet rolling_step() {
  Feet feet = standing(60);
  for (std::uint32_t f = 0; f < 60; ++f) {
    glm::vec3& heel = feet.left_heel[f];
    glm::vec3& toe = feet.left_toe[f];
    if (f < 10) {  // swinging in, 1 m/s, 10 cm up
      heel = glm::vec3(0.1f, 0.1f, -1.0f / kFps * float(10 - f));
      toe = heel + glm::vec3(0.0f, 0.0f, 0.15f);
    } else if (f >= 40) {  // swinging away
      toe = glm::vec3(0.1f, 0.1f, 0.15f + 1.0f / kFps * float(f - 39));
      heel = toe - glm::vec3(0.0f, 0.0f, 0.15f);
    } else {
      heel.y = f < 30 ? 0.0f : 0.05f;  // heel off at 30
      toe.y = f < 15 ? 0.05f : 0.0f;   // toe down at 15
    }
  }
  return feet;
}

TEST(FootContacts, ToeAndHeelApartAndThePlantedFootIsEither) {
  const std::vector<std::uint8_t> c = contacts_of(rolling_step());
  EXPECT_EQ(runs(c, kContactLeftHeel), "[10, 29]");
  EXPECT_EQ(runs(c, kContactLeftToe), "[15, 39]");
  EXPECT_EQ(runs(c, kContactLeft), "[10, 39]");
  EXPECT_EQ(runs(c, kContactRight), "[0, 59]");
  EXPECT_EQ(runs(c, kContactRightToe), "[0, 59]");
  EXPECT_EQ(runs(c, kContactRightHeel), "[0, 59]");
}

TEST(FootContacts, AShortGapOfThePlantedFootHoldsThePointBefore) {
  // The heel leaves at 21, the toe lands at 23: two frames with neither.
  Feet feet = rolling_step();
  for (std::uint32_t f = 10; f < 40; ++f) {
    feet.left_heel[f].y = f <= 20 ? 0.0f : 0.05f;
    feet.left_toe[f].y = f < 23 ? 0.05f : 0.0f;
  }
  const std::vector<std::uint8_t> c = contacts_of(feet);
  EXPECT_EQ(runs(c, kContactLeft), "[10, 39]");
  EXPECT_EQ(runs(c, kContactLeftHeel), "[10, 22]");  // 21 and 22 hold the heel
  EXPECT_EQ(runs(c, kContactLeftToe), "[23, 39]");
}

TEST(FootContacts, SkeletonWithoutToesUsesTheHeel) {
  Feet feet = rolling_step();
  Result<Database> db = build(feet, {}, kFps, /*toes=*/false);
  ASSERT_TRUE(db.ok()) << db.message();
  const AnimationData& a = *db->animation();
  const int left_foot = a.skeleton.find("lFoot");
  const int right_foot = a.skeleton.find("rFoot");
  EXPECT_EQ(a.heel_joints[0], left_foot);
  EXPECT_EQ(a.heel_joints[1], right_foot);
  // contact_joints always name a point: the heel where there is no toe.
  EXPECT_EQ(a.contact_joints[0], left_foot);
  EXPECT_EQ(a.contact_joints[1], right_foot);
  EXPECT_EQ(runs(a.contacts, kContactLeftHeel), "[10, 29]");
  EXPECT_EQ(runs(a.contacts, kContactLeft), "[10, 29]");
  EXPECT_EQ(runs(a.contacts, kContactLeftToe | kContactRightToe), "");
  EXPECT_EQ(runs(a.contacts, kContactRight), "[0, 59]");
}

// A walk in continuous time with marker jitter (+-`amplitude` metres per
// frame on x and z): each foot is still for 0.6 s, then swings 0.7 m forward in
// 0.4 s.
Feet jittered_walk(float fps, std::uint32_t seed, float amplitude = 0.001f) {
  const std::uint32_t frames = static_cast<std::uint32_t>(4.0f * fps);
  Feet feet = standing(frames);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> jitter(-amplitude, amplitude);
  for (std::uint32_t f = 0; f < frames; ++f) {
    for (int s = 0; s < 2; ++s) {
      const float t = float(f) / fps + (s == 0 ? 0.0f : 0.5f);
      const float cycle = std::floor(t);
      const float swing = std::clamp((t - cycle - 0.6f) / 0.4f, 0.0f, 1.0f);
      const float z = 0.7f * (cycle + 0.5f * (1.0f - std::cos(std::numbers::pi_v<float> * swing)));
      const float y = 0.1f * std::sin(std::numbers::pi_v<float> * swing);
      glm::vec3& toe = s == 0 ? feet.left_toe[f] : feet.right_toe[f];
      glm::vec3& heel = s == 0 ? feet.left_heel[f] : feet.right_heel[f];
      heel = glm::vec3(s == 0 ? 0.1f : -0.1f, y, z);
      toe = heel + glm::vec3(0.0f, 0.0f, 0.15f);
      for (glm::vec3* p : {&heel, &toe}) *p += glm::vec3(jitter(rng), 0.0f, jitter(rng));
    }
  }
  return feet;
}

double planted_fraction(const std::vector<std::uint8_t>& contacts, int side) {
  std::size_t n = 0;
  for (std::uint8_t c : contacts) n += (c & contact_planted_bit(side)) ? 1 : 0;
  return contacts.empty() ? 0.0 : double(n) / double(contacts.size());
}

TEST(FootContacts, SameLabelsAt30And120Fps) {
  const std::vector<std::uint8_t> at30 = contacts_of(jittered_walk(30.0f, 1), {}, 30.0f);
  const std::vector<std::uint8_t> at120 = contacts_of(jittered_walk(120.0f, 2), {}, 120.0f);
  for (int side = 0; side < 2; ++side) {
    // Still 60% of the time, and the first steps of a swing are slow
    // (measured: 63.3% at 30 fps, 62.7% at 120 fps).
    EXPECT_GT(planted_fraction(at30, side), 0.55) << side;
    EXPECT_NEAR(planted_fraction(at120, side), planted_fraction(at30, side), 0.02) << side;
  }
  // Measured over single 120 fps frames the same jitter reads as speeds past
  // the thresholds, and stances break up (measured: 47%).
  FootContactParams one_frame;
  one_frame.speed_step_seconds = 0.0f;
  const std::vector<std::uint8_t> jittery = contacts_of(jittered_walk(120.0f, 2), one_frame, 120.0f);
  EXPECT_LT(planted_fraction(jittery, 0), 0.8 * planted_fraction(at120, 0));
}

TEST(FootContacts, AbsoluteHeightsRaiseTheHeel) {
  // Still feet with the toe 1 cm and the heel 7 cm up (an ankle joint above
  // its heel): absolute heights plant both (the heel's floor is
  // heel_height_extra), and not once the feet are 4 cm higher.
  Feet feet = standing(60);
  for (std::uint32_t f = 0; f < 60; ++f) {
    const float up = f < 30 ? 0.0f : 0.04f;
    feet.left_toe[f].y = 0.01f + up;
    feet.left_heel[f].y = 0.07f + up;
  }
  FootContactParams absolute;
  absolute.height_above_clip_floor = false;
  const std::vector<std::uint8_t> c = contacts_of(feet, absolute);
  EXPECT_EQ(runs(c, kContactLeftToe), "[0, 29]");
  EXPECT_EQ(runs(c, kContactLeftHeel), "[0, 29]");
}

TEST(FootContacts, TheFeatureChannelReadsThePlantedBits) {
  std::vector<MotionClip> clips(1);
  clips[0].meta.file = "feet.bvh";
  clips[0].motion = motion_of(rolling_step(), kFps);
  MotionBuildSettings settings;
  Result<FeatureSchema> schema = parse_schema_json(
      R"({"channels": [{"name": "contact", "kind": "foot_contact"},
                       {"name": "foot", "kind": "bone_position", "bone": "@left_foot"}]})",
      "schema");
  ASSERT_TRUE(schema.ok()) << schema.message();
  settings.schema = *schema;
  settings.edge_rule = EdgeRule::Clamp;
  Result<Database> db = build_database_from_motions(clips, settings);
  ASSERT_TRUE(db.ok()) << db.message();
  for (std::uint32_t f = 0; f < db->frame_count(); ++f) {
    const std::uint8_t bits = db->animation()->contacts[f];
    for (std::uint32_t d = 0; d < 2; ++d) {
      const float raw = db->row(f)[d] * db->normalization()[d].scale + db->normalization()[d].offset;
      EXPECT_NEAR(raw, (bits & contact_planted_bit(int(d))) ? 1.0f : 0.0f, 1e-5f) << "frame " << f << " dim " << d;
    }
  }
}

TEST(FootContacts, ParametersAreValidatedBeforeTheBuild) {
  FootContactParams bad;
  bad.exit_speed = 0.01f;  // below enter_speed
  Result<Database> db = build(standing(60), bad);
  ASSERT_FALSE(db.ok());
  EXPECT_NE(db.message().find("contacts.exit_speed: must be >= enter_speed"), std::string::npos) << db.message();
  bad = {};
  bad.min_gap_seconds = std::nanf("");
  db = build(standing(60), bad);
  ASSERT_FALSE(db.ok());
  EXPECT_NE(db.message().find("contacts.min_gap_seconds: must be a finite number >= 0"), std::string::npos)
      << db.message();
}

// ---- the .mmdb ---------------------------------------------------------

FootContactParams unusual_params() {
  FootContactParams p;
  p.enter_height = 0.021f;
  p.exit_height = 0.033f;
  p.enter_speed = 0.055f;
  p.exit_speed = 0.077f;
  p.min_contact_seconds = 0.12f;
  p.min_gap_seconds = 0.07f;
  p.speed_step_seconds = 0.02f;
  p.floor_percentile = 0.1f;
  p.heel_height_extra = 0.05f;
  return p;
}

TEST(FootContactsFile, LabelsJointsAndParametersRoundTrip) {
  Result<Database> db = build(rolling_step(), unusual_params());
  ASSERT_TRUE(db.ok()) << db.message();
  const std::string bytes = serialize_database(*db);
  EXPECT_EQ(bytes[8], char(7));  // the build's measured gait bands (format 7) carry the version 5 animation section
  Result<Database> back = deserialize_database(bytes, "feet.mmdb");
  ASSERT_TRUE(back.ok()) << back.message();
  const AnimationData& a = *db->animation();
  const AnimationData& b = *back->animation();
  EXPECT_EQ(b.contacts, a.contacts);
  EXPECT_EQ(b.contact_joints, a.contact_joints);
  EXPECT_EQ(b.heel_joints, a.heel_joints);
  EXPECT_EQ(a.heel_joints[0], a.skeleton.find("Foot_L"));
  EXPECT_EQ(a.contact_joints[1], a.skeleton.find("Toes_R"));
  EXPECT_FALSE(b.legacy_contacts);
  const FootContactParams& p = b.contact_params;
  const FootContactParams q = unusual_params();
  EXPECT_EQ(p.left_toe, q.left_toe);
  EXPECT_EQ(p.right_heel, q.right_heel);
  EXPECT_EQ(p.enter_height, q.enter_height);
  EXPECT_EQ(p.exit_height, q.exit_height);
  EXPECT_EQ(p.enter_speed, q.enter_speed);
  EXPECT_EQ(p.exit_speed, q.exit_speed);
  EXPECT_EQ(p.min_contact_seconds, q.min_contact_seconds);
  EXPECT_EQ(p.min_gap_seconds, q.min_gap_seconds);
  EXPECT_EQ(p.speed_step_seconds, q.speed_step_seconds);
  EXPECT_EQ(p.floor_percentile, q.floor_percentile);
  EXPECT_EQ(p.heel_height_extra, q.heel_height_extra);
  EXPECT_EQ(p.height_above_clip_floor, q.height_above_clip_floor);
  EXPECT_EQ(back->content_hash(), db->content_hash());
}

void put_u32(std::string& bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

std::uint32_t get_u32(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t{static_cast<std::uint8_t>(bytes[at + i])} << (8 * i);
  return v;
}

// The same database as a format 3 or 4 file would hold it: the old contact
// setup (one joint per side, max height and 3-D speed) and planted bits
// alone; format 3 without the import units' presence byte. Made from the
// database as a format 5 file would hold it: without the gait bands that
// format 7 adds (their tags stay, as ordinary per-frame tags).
std::string as_old_format(const Database& measured, std::uint32_t version) {
  DatabaseParts parts = measured.parts();
  parts.gait_bands.reset();
  Result<Database> unmeasured = Database::create(std::move(parts));
  EXPECT_TRUE(unmeasured.ok()) << unmeasured.message();
  const Database& db = *unmeasured;
  std::string bytes = serialize_database(db);
  const AnimationData& a = *db.animation();
  // The new setup starts 16 bytes (4 joints) before the left toe's name.
  const std::string name = a.contact_params.left_toe;
  std::string key(4, '\0');
  put_u32(key, 0, static_cast<std::uint32_t>(name.size()));
  key += name;
  const std::size_t at = bytes.find(key);
  EXPECT_NE(at, std::string::npos);
  const std::size_t begin = at - 16;
  std::size_t end = at;
  for (int s = 0; s < 4; ++s) end += 4 + get_u32(bytes, end);
  end += 9 * 4 + 1;
  std::string old(8, '\0');
  put_u32(old, 0, static_cast<std::uint32_t>(a.contact_joints[0]));
  put_u32(old, 4, static_cast<std::uint32_t>(a.contact_joints[1]));
  for (const std::string& bone : {a.contact_params.left_toe, a.contact_params.right_toe}) {
    std::string s(4, '\0');
    put_u32(s, 0, static_cast<std::uint32_t>(bone.size()));
    old += s + bone;
  }
  for (float v : {0.02f, 0.6f, 0.06f}) {
    std::string s(4, '\0');
    std::memcpy(s.data(), &v, 4);
    old += s;
  }
  old += '\1';
  const float percentile = 0.05f;
  old.append(reinterpret_cast<const char*>(&percentile), 4);
  bytes.replace(begin, end - begin, old);
  // The contacts are the last frame_count bytes of the payload.
  const std::size_t contacts = bytes.size() - 8 - a.frame_count;
  for (std::size_t f = 0; f < a.frame_count; ++f) bytes[contacts + f] &= kContactLeft | kContactRight;
  if (version == 3) {
    // The units' presence byte (0) comes right before the animation's (1),
    // which the joint count and the first joint's name follow.
    std::string section("\0\1", 2);
    std::string counts(8, '\0');
    put_u32(counts, 0, static_cast<std::uint32_t>(a.joint_count()));
    put_u32(counts, 4, static_cast<std::uint32_t>(a.skeleton.names[0].size()));
    const std::size_t units = bytes.find(section + counts + a.skeleton.names[0]);
    EXPECT_NE(units, std::string::npos);
    if (units != std::string::npos) bytes.erase(units, 1);
  }
  put_u32(bytes, 8, version);
  fuzz::repair_mmdb(bytes);
  return bytes;
}

TEST(FootContactsFile, FormatsThreeAndFourLoadWithTheirPlantedBitsOnTheirPoint) {
  for (auto [version, toes] : {std::pair{3u, true}, std::pair{3u, false}, std::pair{4u, true}}) {
    SCOPED_TRACE("format " + std::to_string(version) + (toes ? ", toes" : ", no toes (DAZ)"));
    Result<Database> db = build(rolling_step(), {}, kFps, toes);
    ASSERT_TRUE(db.ok()) << db.message();
    Result<Database> old = deserialize_database(as_old_format(*db, version), "old.mmdb");
    ASSERT_TRUE(old.ok()) << old.message();
    const AnimationData& a = *db->animation();
    const AnimationData& b = *old->animation();
    EXPECT_TRUE(b.legacy_contacts);
    EXPECT_EQ(b.contact_joints, a.contact_joints);
    EXPECT_EQ(b.heel_joints, a.heel_joints);
    EXPECT_EQ(b.contact_params.enter_speed, 0.6f);
    EXPECT_EQ(b.contact_params.exit_speed, 0.6f);
    EXPECT_EQ(b.contact_params.min_contact_seconds, 0.0f);
    // The old planted bit gains the bit of the joint it was detected on.
    const std::uint8_t point = toes ? kContactLeftToe : kContactLeftHeel;
    for (std::uint32_t f = 0; f < a.frame_count; ++f) {
      const bool planted = (a.contacts[f] & kContactLeft) != 0;
      EXPECT_EQ(b.contacts[f] & (kContactLeft | kContactLeftToe | kContactLeftHeel),
                planted ? kContactLeft | point : 0)
          << "frame " << f;
    }
  }
}

TEST(FootContactsFile, EveryCutInTheContactSetupIsAnError) {
  Result<Database> db = build(rolling_step());
  ASSERT_TRUE(db.ok()) << db.message();
  const std::string bytes = serialize_database(*db);
  const std::string name = db->animation()->contact_params.left_toe;
  const std::size_t at = bytes.find(name);
  ASSERT_NE(at, std::string::npos);
  // Cut a byte anywhere from the joints to the parameters, with the header
  // and checksum made good again (as a fuzzer's mutation would reach it).
  for (std::size_t cut = at - 20; cut < at + 100; ++cut) {
    std::string damaged = bytes;
    damaged.erase(cut, 1);
    fuzz::repair_mmdb(damaged);
    Result<Database> loaded = deserialize_database(damaged, "cut.mmdb");
    EXPECT_FALSE(loaded.ok()) << "cut at " << cut;
    if (!loaded.ok()) {
      EXPECT_NE(loaded.message().find("cut.mmdb: "), std::string::npos) << loaded.message();
    }
  }
}

}  // namespace
}  // namespace mmvk
