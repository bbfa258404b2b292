// Start here: the public API a newcomer needs, in one include.
//
//   #include "mmvk/mmvk.hpp"
//
// The library is mmvk::runtime (CPU, no global state, no environment
// variables); the Vulkan backend is the separate mmvk::vulkan target, whose
// headers live under mmvk/vulkan/ and are not included here. What a call
// can fail with comes back as an mmvk::Status or mmvk::Result<T>
// (status.hpp) whose message names the field or file at fault.
// host/examples/cpp/crowd_example.cpp uses exactly this header.
//
// The layers, lowest first (runtime/README.md has the full map); each uses
// only the ones before it:
//   common     Status and Result, ThreadPool (the caller owns the threads),
//              atomic file writes                   status.hpp thread_pool.hpp file_io.hpp
//   import     BVH (and FBX/glTF) motion, the skeleton's bone roles
//                                                   bvh.hpp motion.hpp character.hpp
//   features   the feature schema: channels, weights, normalization
//                                                   feature_schema.hpp
//   database   the manifest, the build, the immutable Database, .mmdb files
//                                                   manifest.hpp database_build.hpp database.hpp database_io.hpp
//   clusters   k-means cluster tables for the cluster backends
//                                                   cluster_table.hpp
//   search     the search semantics and its backends, made by name
//                                                   search.hpp backends.hpp async_search.hpp
//   query      queries by channel name, or batched for a crowd
//                                                   query_builder.hpp
//   animation  the CrowdController: B characters, one batched search per tick
//                                                   crowd_controller.hpp
//
// The usual path: load_manifest -> build_database (or load_database) ->
// cpu_backends().make(spec, database) -> backend->search(batch, k, out), and
// for characters CrowdController::create -> place -> tick -> world_positions.
#pragma once

#include "mmvk/common/status.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "mmvk/common/file_io.hpp"

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/import/motion.hpp"

#include "mmvk/features/feature_schema.hpp"

#include "mmvk/database/database.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/database/manifest.hpp"

#include "mmvk/clusters/cluster_table.hpp"

#include "mmvk/search/async_search.hpp"
#include "mmvk/search/backends.hpp"
#include "mmvk/search/search.hpp"

#include "mmvk/query/query_builder.hpp"

#include "mmvk/animation/crowd_controller.hpp"
