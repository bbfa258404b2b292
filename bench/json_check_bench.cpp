// The strict JSON check (mmvk/common/json_check.hpp: duplicate keys, trailing
// bytes, depth) on crowd scenarios of 8, 16 and 46 MB: arrays of agent
// objects as `mmvk crowd --scenario` reads them, the shape whose check was
// quadratic in the number of objects (nlohmann's callback parser). The
// time per byte (the bytes_per_second counter) should stay the same across
// the three sizes.
//
//   build/bench/mmvk_bench --benchmark_filter=BM_StrictJsonCheck
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "mmvk/common/json_check.hpp"

namespace mmvk::bench {
namespace {

// A scenario of about `megabytes` MB: each agent a start, three goals, a
// speed and its tags (about 120 bytes).
std::string scenario_text(std::size_t megabytes) {
  std::string text = "{\"world_size_m\": 200, \"agents\": [\n";
  char agent[256];
  for (std::size_t a = 0; text.size() < megabytes * 1000 * 1000; ++a) {
    const double x = double(a % 1000) * 0.1, z = double(a / 1000) * 0.1;
    std::snprintf(agent, sizeof(agent),
                  "%s{\"start\": [%.2f, %.2f], \"goals\": [[%.2f, %.2f], [%.2f, %.2f], [1.5, 2.5]], "
                  "\"speed\": \"walk\", \"require_tags\": [\"walk\"]}\n",
                  a == 0 ? "" : ",", x, z, z, x, x + 1.0, z + 1.0);
    text += agent;
  }
  return text + "]}\n";
}

void BM_StrictJsonCheck(benchmark::State& state) {
  const std::string text = scenario_text(std::size_t(state.range(0)));
  for (auto _ : state) {
    const Status status = check_json_text(text, "scenario.json");
    if (!status.ok()) {
      state.SkipWithError(status.message().c_str());
      break;
    }
  }
  state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(text.size()));
  state.counters["bytes"] = double(text.size());
}

BENCHMARK(BM_StrictJsonCheck)->ArgName("MB")->Arg(8)->Arg(16)->Arg(46)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mmvk::bench
