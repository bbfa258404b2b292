// The build's check of an import: a person's motion, read with the right
// units and up axis, stands 0.5 to 2.5 m tall, upright along +Y, on a floor
// near y = 0, and walks slower than 4 m/s. A wrong metres_per_unit (a
// centimetre file read as metres: 26 m tall, 150 m/s) or up axis (a Y-up
// file read as Z-up: the body lies along -Z) otherwise builds silently and
// surfaces later as nonsense in the crowd. The measures apply to skeletons
// whose feet and head resolve by role (character.hpp); others (a tentacle,
// a box) are not checked.
#pragma once

#include <string>

#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

inline constexpr float kMinStandingHeight = 0.5f;  // metres: below is a small child or wrong units
inline constexpr float kMaxStandingHeight = 2.5f;  // metres: above is wrong units
inline constexpr float kMinBodyUp = 0.5f;          // mean feet-to-head direction's y: below, the body is not upright
inline constexpr float kMaxWalkSpeed = 4.0f;       // m/s, for clips tagged "walk" (a brisk walk is 2)
inline constexpr float kMaxRootSpeed = 12.0f;      // m/s, for any clip (a sprinter averages 10)

struct ImportMeasures {
  bool human = false;           // the roles @left_foot, @right_foot and @head resolved; the rest is 0 otherwise
  float standing_height = 0.0f;  // metres: 90th percentile over frames of the highest joint's y minus the lowest's
  float floor = 0.0f;           // metres: the median over frames of the lowest joint's y
  float body_up = 0.0f;         // mean over frames of the unit feet-to-head vector's y (1 = upright)
  float root_speed = 0.0f;      // m/s: the median horizontal speed of the hips (@hips, else the root joint)
};

// Forward kinematics of every frame (at most 4096, evenly spread, for the
// height, the floor and the body's axis).
ImportMeasures measure_import(const Motion& motion);

// What the import used, for the message's causes and fixes.
struct ImportContext {
  std::string source;           // the file, and its animation for a scene file
  float metres_per_unit = 1.0f;
  std::string units_from;       // "guessed from the skeleton's size", "the manifest's import.metres_per_unit", ...
  UpAxis up_axis = UpAxis::Y;   // the manifest's up_axis for BVH (Y unless given)
  std::string axes_from;
  bool walk = false;            // the clip is tagged "walk": its speed limit is kMaxWalkSpeed
};

// An error when the measures are implausible, naming the figure, its
// plausible range, the likely cause (units, up axis, frame rate) and the
// manifest field that fixes it ("import": {"metres_per_unit": ...},
// {"up_axis": ...}) or accepts it ({"accept_implausible": true}).
Status check_import(const ImportMeasures& measures, const ImportContext& context);

}  // namespace mmvk
