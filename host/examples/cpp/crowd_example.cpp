// mmvk from C++ in one file: build a database, search it, and walk a small
// crowd of characters with velocities of your own.
//
//   build/host/examples/cpp/mmvk_crowd_example host/crowd/data/cmu131/manifest.json
//
// The argument is a manifest (docs/database.md) or a folder of BVH files.
// Only the start-here header is included: everything here is mmvk::runtime's
// public API, on the CPU (the Vulkan backends are the same calls made with
// another name; runtime/vulkan/README.md).
#include <cmath>
#include <cstdio>
#include <memory>
#include <span>
#include <vector>

#include <glm/geometric.hpp>

#include "mmvk/mmvk.hpp"

namespace {

constexpr std::uint32_t kCharacters = 4;
constexpr float kRateHz = 30.0f;
constexpr int kTicks = 90;  // 3 s

int fail(const char* what, const std::string& message) {
  std::fprintf(stderr, "crowd_example: %s: %s\n", what, message.c_str());
  return 1;
}

// 1. A database: the manifest's clips, their features and animation.
mmvk::Result<mmvk::Database> build(const char* path, mmvk::ThreadPool& pool) {
  MMVK_ASSIGN_OR_RETURN(const mmvk::Manifest manifest, mmvk::load_manifest_or_directory(path));
  mmvk::BuildOptions options;
  options.pool = &pool;
  return mmvk::build_database(manifest, options);
}

// 2. A search: a frame's own features must find that frame, at cost 0.
mmvk::Status search_own_frame(mmvk::SearchBackend& backend, const mmvk::Database& db) {
  std::uint32_t frame = db.frame_count() / 2;
  while (frame < db.frame_count() && !mmvk::is_candidate(db, frame, {})) ++frame;
  if (frame == db.frame_count()) return mmvk::make_error("no candidate frame in the second half of the database");
  std::vector<mmvk::Match> best(1);
  MMVK_TRY(backend.search(mmvk::QueryBatch{db.row(frame), {}, 1}, 1, best));
  std::printf("search: frame %u's features found frame %u at cost %g (%s on %s)\n", frame, best[0].frame,
              double(best[0].cost), std::string(backend.name()).c_str(), backend.device().c_str());
  if (best[0].frame != frame) return mmvk::make_error("the search did not find the query's own frame");
  return {};
}

// 3. A crowd: each character walks its own way at 0.6 m/s for 3 s.
mmvk::Status walk(mmvk::SearchBackend& backend, const mmvk::Database& db, mmvk::ThreadPool& pool) {
  MMVK_ASSIGN_OR_RETURN(mmvk::CrowdController crowd, mmvk::CrowdController::create(db, kCharacters));
  std::vector<glm::vec3> velocity(kCharacters);
  for (std::uint32_t b = 0; b < kCharacters; ++b) {
    MMVK_TRY(crowd.place(b, glm::vec3(3.0f * float(b), 0.0f, 0.0f), 0.0f));
    const float heading = 0.5f * float(b);  // radians from +z
    velocity[b] = 0.6f * glm::vec3(std::sin(heading), 0.0f, std::cos(heading));
  }
  // The world joint positions, [characters x joints], are those of the last
  // tick's displayed poses: the start is taken after a first tick.
  const std::size_t joints = crowd.animation().joint_count();
  const float dt = 1.0f / kRateHz;
  MMVK_TRY(crowd.tick(dt, mmvk::CrowdInput{velocity, {}}, backend, pool));
  const std::vector<glm::vec3> start(crowd.world_positions().begin(), crowd.world_positions().end());
  for (int tick = 0; tick < kTicks; ++tick) MMVK_TRY(crowd.tick(dt, mmvk::CrowdInput{velocity, {}}, backend, pool));
  const std::span<const glm::vec3> now = crowd.world_positions();
  // The root joint's (the hips') way over the ground, against the velocity asked for.
  for (std::uint32_t b = 0; b < kCharacters; ++b) {
    glm::vec3 moved = now[b * joints] - start[b * joints];
    moved.y = 0.0f;
    const float along = glm::dot(moved, glm::normalize(velocity[b]));
    std::printf("character %u: hips at (%.2f, %.2f, %.2f) m, %.2f m along its velocity in %.0f s\n", b,
                double(now[b * joints].x), double(now[b * joints].y), double(now[b * joints].z), double(along),
                double(kTicks / kRateHz));
    if (!(along > 0.5f)) return mmvk::make_error("character " + std::to_string(b) + " did not walk its way");
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s manifest.json|bvh-folder\n", argv[0]);
    return 2;
  }
  mmvk::ThreadPool pool;  // the caller's threads, lent to every call below
  mmvk::Result<mmvk::Database> db = build(argv[1], pool);
  if (!db) return fail("build", db.message());
  std::printf("database: %u frames x %u dims, %zu clips\n", db->frame_count(), db->dims(), db->clips().size());

  mmvk::BackendSpec spec;
  spec.name = "fast-box";  // any name of cpu_backends().names()
  spec.pool = &pool;
  mmvk::Result<std::unique_ptr<mmvk::SearchBackend>> backend = mmvk::cpu_backends().make(spec, *db);
  if (!backend) return fail("backend", backend.message());
  if (mmvk::Status found = search_own_frame(**backend, *db); !found) return fail("search", found.message());
  if (mmvk::Status walked = walk(**backend, *db, pool); !walked) return fail("crowd", walked.message());
  std::printf("ok: every character walked its own way\n");
  return 0;
}
