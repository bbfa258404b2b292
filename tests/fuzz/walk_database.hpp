// The generated walk (a 40-frame, 30 fps, 5-joint BVH whose names resolve to
// the default schema's bone roles) and the database built from it with the
// default schema: make_seeds writes them as seeds, and fuzz targets that
// need a database with bone channels (pose targets) search it.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "mmvk/import/bvh.hpp"
#include "mmvk/database/database_build.hpp"

namespace mmvk::fuzz {

inline std::string walk_bvh() {
  std::string text =
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 100 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      " JOINT UpperLeg_L\n {\n  OFFSET 10 -5 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "  JOINT Foot_L\n  {\n   OFFSET 0 -90 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "   End Site\n   {\n    OFFSET 0 -5 10\n   }\n  }\n }\n"
      " JOINT UpperLeg_R\n {\n  OFFSET -10 -5 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "  JOINT Foot_R\n  {\n   OFFSET 0 -90 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "   End Site\n   {\n    OFFSET 0 -5 10\n   }\n  }\n }\n}\n"
      "MOTION\nFrames: 40\nFrame Time: 0.0333333\n";
  char line[256];
  for (int f = 0; f < 40; ++f) {
    const double swing = 25.0 * std::sin(f * 0.3);
    std::snprintf(line, sizeof(line), "0 100 %.2f 0 0 %.2f 0 %.2f 0 0 0 0 0 %.2f 0 0 0 0\n", f * 4.0, f * 1.5, swing,
                  -swing);
    text += line;
  }
  return text;
}

// The walk's database (default schema, clamp edge rule), or the error.
inline Result<Database> build_walk_database() {
  MMVK_ASSIGN_OR_RETURN(BvhFile file, parse_bvh(walk_bvh(), "walk.bvh"));
  MMVK_ASSIGN_OR_RETURN(Motion motion, motion_from_bvh(file, {}));
  std::vector<MotionClip> clips(1);
  clips[0].meta.file = "walk.bvh";
  clips[0].meta.name = "walk";
  clips[0].meta.tags = {"walk"};
  clips[0].motion = std::move(motion);
  MotionBuildSettings settings;
  settings.edge_rule = EdgeRule::Clamp;
  return build_database_from_motions(clips, settings);
}

// Built once per process (fuzz targets call it on every input).
inline const Database& walk_database() {
  static const Database db = std::move(build_walk_database()).value();
  return db;
}

}  // namespace mmvk::fuzz
