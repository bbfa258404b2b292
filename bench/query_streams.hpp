// The three query streams of the search benchmarks, drawn deterministically
// from a database's own rows:
//   Continue   - a random frame's features plus small Gaussian noise (what a
//                character asks while it plays a clip smoothly)
//   Transition - the pose channels (bones, velocities) of one random frame
//                with the trajectory channels of another (a change of intent)
//   Uniform    - every dimension uniform within the database's range
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "mmvk/database/database.hpp"

namespace mmvk::bench {

enum class QueryStream { Continue, Transition, Uniform };

std::string_view query_stream_name(QueryStream stream);

// [count x dims] normalized query features.
std::vector<float> make_queries(const Database& database, QueryStream stream, std::size_t count,
                                std::uint64_t seed = 42);

}  // namespace mmvk::bench
