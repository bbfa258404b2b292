// Pose-matching queries: "which frame puts these end effectors here?", the
// data-driven IK use of a motion database. Targets are positions (and
// optionally velocities) of named bones in character space; the query sets
// the database's bone_position / bone_velocity channels of those bones and
// gives every other channel weight 0, so the search returns the recorded
// frame whose end effectors come closest (in the channels' normalized,
// weighted distance): a natural whole-body pose that reaches the targets,
// which an IK pass can then refine (docs/search.md, "Pose matching").
//
//   MMVK_ASSIGN_OR_RETURN(auto targets, mmvk::load_pose_targets("reach.json"));
//   MMVK_ASSIGN_OR_RETURN(auto query, mmvk::build_pose_query(db, targets));
//   backend.search({query.features, {&query.params, 1}, 1}, 1, match);
//
// Targets file (JSON; unknown fields are errors naming the file and field):
// { "targets": [
//     { "bone": "@left_foot", "position": [0.1, 0.05, 0.3],    // metres
//       "velocity": [0, 0, 1.2] },                             // m/s, optional
//     { "bone": "RightHand", "velocity": [0.5, 0, 0] } ] }     // either may be alone
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

struct PoseTarget {
  // A joint name or role, as the schema's channels name bones ("@left_foot");
  // with an animation section, any name of the same joint works.
  std::string bone;
  std::optional<glm::vec3> position;  // character space, metres
  std::optional<glm::vec3> velocity;  // character space, metres per second
};

struct PoseQuery {
  std::vector<float> features;     // [dims], normalized
  QueryParams params;              // weights: the targeted channels' as in the schema, others 0
  std::vector<std::size_t> channels;  // schema indices of the targeted channels, one or two per target
};

// Parses a targets file; `source` names it in messages ("t.json: targets[1].position: ...").
Result<std::vector<PoseTarget>> parse_pose_targets_json(std::string_view json_text, std::string_view source);
Result<std::vector<PoseTarget>> load_pose_targets(const std::filesystem::path& path);

// Builds the query. Each position goes to the bone_position channel of its
// bone, each velocity to its bone_velocity channel (or the root_velocity
// channel, whose bone is the hips by default). Errors name `source` and the
// target: a bone with no such channel (listing the channels there are), a
// bone named twice, no target.
Result<PoseQuery> build_pose_query(const Database& database, std::span<const PoseTarget> targets,
                                   std::string_view source = "pose targets");

// How far frame `frame`'s recorded values lie from each target: [targets],
// the position distance in metres (or -1 without a position target) and the
// velocity distance in m/s (or -1). Precondition: build_pose_query accepted
// the targets.
struct PoseTargetError {
  float position_metres = -1.0f;
  float velocity_metres_per_second = -1.0f;
};
std::vector<PoseTargetError> pose_target_errors(const Database& database, std::uint32_t frame,
                                                std::span<const PoseTarget> targets);

}  // namespace mmvk
