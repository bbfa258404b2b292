// Foot contacts on real motion capture, through `mmvk build` and `mmvk
// inspect`: on Bandai locomotion at its own 30 fps, the frames flagged
// planted move their toe less than 2 cm/s on average while each foot stays
// planted on at least 35% of the frames (the targets of the issue that asked
// for these labels); the default crowd data (CMU 131) keeps its measured
// figures; a manifest's "contacts" block reaches the build, and a bad one is
// an error naming the field.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "mmvk/features/foot_contacts.hpp"
#include "support/cli_fixture.hpp"
#include "support/command.hpp"

namespace mmvk {
namespace {

class FootContactsData : public test::CliFixture {
 protected:
  // Builds `source` (a folder or manifest) into dir_/name.mmdb and returns
  // `mmvk inspect --json`'s animation.contacts.
  nlohmann::json contacts_of(const std::string& source, const std::string& name) {
    const std::string db = (dir_ / (name + ".mmdb")).string();
    const test::CommandResult built = test::run_command(mmvk_ + " build '" + source + "' -o '" + db + "'");
    EXPECT_EQ(built.exit_code, 0) << built.output;
    const test::CommandResult inspected = test::run_command(mmvk_ + " inspect '" + db + "' --json");
    EXPECT_EQ(inspected.exit_code, 0) << inspected.output;
    const nlohmann::json out = nlohmann::json::parse(inspected.output, nullptr, false);
    EXPECT_FALSE(out.is_discarded()) << inspected.output;
    if (out.is_discarded() || !out["animation"].contains("contacts")) return nlohmann::json::object();
    const nlohmann::json contacts = out["animation"]["contacts"];
    for (const char* side : {"left", "right"}) {
      for (const char* point : {"planted", "toe", "heel"}) {
        const nlohmann::json& p = contacts["feet"][side][point];
        std::printf("%s %-5s %-7s %-12s %5.1f%% of frames, %.2f cm/s, %.1f%% of pairs > 10 cm/s\n", name.c_str(),
                    side, point, p["joint"].get<std::string>().c_str(), 100.0 * p["fraction"].get<double>(),
                    p["mean_speed_cm_s"].is_number() ? p["mean_speed_cm_s"].get<double>() : -1.0,
                    p["fast_fraction"].is_number() ? 100.0 * p["fast_fraction"].get<double>() : -1.0);
      }
    }
    return contacts;
  }

  std::string write_manifest(const std::string& name, const std::string& text) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
};

TEST_F(FootContactsData, BandaiLocomotionPlantedFeetStayPut) {
  const nlohmann::json c = contacts_of((data_ / "bandai-namco-nc/locomotion-normal").string(), "loco");
  ASSERT_TRUE(c.contains("feet")) << c.dump();
  EXPECT_EQ(c["toe_joints"], nlohmann::json({"Toes_L", "Toes_R"}));
  EXPECT_EQ(c["heel_joints"], nlohmann::json({"Foot_L", "Foot_R"}));
  EXPECT_FALSE(c["legacy"].get<bool>());
  EXPECT_EQ(c["params"]["enter_speed"].get<float>(), FootContactParams{}.enter_speed);
  for (const char* side : {"left", "right"}) {
    SCOPED_TRACE(side);
    const nlohmann::json& foot = c["feet"][side];
    // The targets (measured: 38.2% / 38.0% planted, 1.79 / 1.73 cm/s).
    EXPECT_GE(foot["planted"]["fraction"].get<double>(), 0.35);
    EXPECT_LE(foot["planted"]["mean_speed_cm_s"].get<double>(), 2.0);
    // Planted means a point is down: it covers both points' frames.
    EXPECT_GE(foot["planted"]["frames"].get<std::uint64_t>(), foot["toe"]["frames"].get<std::uint64_t>());
    EXPECT_GE(foot["planted"]["frames"].get<std::uint64_t>(), foot["heel"]["frames"].get<std::uint64_t>());
    EXPECT_GT(foot["heel"]["fraction"].get<double>(), 0.2);
    // Heel strikes and toe-offs are no longer inside the contacts (before
    // these labels, 12% of the flagged frame pairs moved faster than 10 cm/s).
    EXPECT_LT(foot["planted"]["fast_fraction"].get<double>(), 0.01);
    EXPECT_LE(foot["heel"]["mean_speed_cm_s"].get<double>(), 2.5);
  }
  // The text form says the same per foot and point.
  const test::CommandResult text = test::run_command(mmvk_ + " inspect '" + (dir_ / "loco.mmdb").string() + "'");
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_NE(text.output.find("contacts: enter below clip floor + 0.02 m and 0.05 m/s horizontal"), std::string::npos)
      << text.output;
  for (const char* row : {"left   planted  Toes_L", "left   toe      Toes_L", "left   heel     Foot_L",
                          "right  planted  Toes_R", "right  heel     Foot_R"}) {
    EXPECT_NE(text.output.find(row), std::string::npos) << row << "\n" << text.output;
  }
}

TEST_F(FootContactsData, DefaultCrowdDataKeepsItsFigures) {
  const std::filesystem::path manifest = test::test_source_dir() / ".." / "host" / "crowd" / "data" / "cmu131" /
                                         "manifest.json";
  const nlohmann::json c = contacts_of(manifest.string(), "cmu131");
  ASSERT_TRUE(c.contains("feet")) << c.dump();
  for (const char* side : {"left", "right"}) {
    SCOPED_TRACE(side);
    const nlohmann::json& planted = c["feet"][side]["planted"];
    // Measured 38.1% at 3.27 cm/s (noisier CMU markers; the old labels
    // flagged 48% at 8.8 cm/s).
    EXPECT_GE(planted["fraction"].get<double>(), 0.33);
    EXPECT_LE(planted["mean_speed_cm_s"].get<double>(), 4.0);
  }
  // Mirrored copies make the two feet alike.
  EXPECT_EQ(c["feet"]["left"]["planted"]["frames"], c["feet"]["right"]["planted"]["frames"]);
}

TEST_F(FootContactsData, ManifestContactsReachTheBuild) {
  const std::string clips = "\"clips\": [\"" + (data_ / "bandai-namco-nc/locomotion-normal").string() +
                            "/dataset-2_walk_normal_001.bvh\"]";
  const nlohmann::json strict = contacts_of(write_manifest("strict.json", "{" + clips + "}"), "strict");
  const nlohmann::json loose = contacts_of(
      write_manifest("loose.json", R"({"contacts": {"enter_speed": 0.2, "exit_speed": 0.4}, )" + clips + "}"), "loose");
  ASSERT_TRUE(strict.contains("feet") && loose.contains("feet"));
  EXPECT_EQ(loose["params"]["exit_speed"].get<float>(), 0.4f);
  EXPECT_GT(loose["feet"]["left"]["planted"]["frames"].get<std::uint64_t>(),
            strict["feet"]["left"]["planted"]["frames"].get<std::uint64_t>());

  const test::CommandResult bad = test::run_command(
      mmvk_ + " build '" + write_manifest("bad.json", R"({"contacts": {"exit_speed": -1}, )" + clips + "}") +
      "' -o '" + (dir_ / "bad.mmdb").string() + "'");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("bad.json: contacts.exit_speed: must be a finite number >= 0"), std::string::npos)
      << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.mmdb"));
}

}  // namespace
}  // namespace mmvk
