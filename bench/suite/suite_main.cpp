// mmvk_suite's main: Google Benchmark's, after one environment fix-up.
//
// FAISS runs on OpenMP, and GNU OpenMP's idle threads spin for a while
// before sleeping (OMP_WAIT_POLICY unset). On a machine shared with other
// jobs, spinning threads hold the cores the threads doing the work need:
// measured here, faiss-flat at B = 1024 on locomotion took about 5x longer than
// with OMP_WAIT_POLICY=passive, while mmvk's own thread pool, which sleeps
// on a condition variable, was unaffected. libgomp reads the variable when
// it is loaded, before main(), so the suite sets it and runs itself again
// when the caller has not chosen a policy. The policy in effect is recorded
// in the benchmark context (omp_wait_policy).
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  if (policy == nullptr) {
    setenv("OMP_WAIT_POLICY", "passive", 1);
    execv("/proc/self/exe", argv);
    std::perror("mmvk_suite: cannot run itself again with OMP_WAIT_POLICY=passive; continuing without it");
  }
  benchmark::AddCustomContext("omp_wait_policy", policy != nullptr ? policy : "unset");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
