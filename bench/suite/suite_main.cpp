// mmvk_suite's main: Google Benchmark's, after the environment fix-ups
// that FAISS's speed depends on and that must be in place before its
// libraries load (the suite sets them and runs itself again; the JSON
// context records what was in force):
//
// - OMP_WAIT_POLICY=passive unless set. FAISS runs on OpenMP, and GNU
//   OpenMP's idle threads spin for a while before sleeping. On a machine
//   shared with other jobs, spinning threads hold the cores the threads
//   doing the work need: measured here, faiss-flat at B = 1024 on
//   locomotion took about 5x longer than with OMP_WAIT_POLICY=passive,
//   while mmvk's own thread pool, which sleeps on a condition variable, was
//   unaffected. On an idle machine `active` can be faster (2 cores:
//   302 against 475 us/query at 417k, B = 1024, 2 threads); set it to
//   measure that.
// - OPENBLAS_CORETYPE=SkylakeX unless the caller set a core type, when the
//   CPU has the AVX-512 subsets those kernels use and OpenBLAS picked its
//   AVX2 kernels (Haswell or Zen) for it: Debian's OpenBLAS 0.3.21 does not
//   know AMD's AVX-512 CPUs. Measured on a 2-core AMD EPYC (417k
//   frames, B = 1024, one thread): faiss-flat 622 -> 459 us/query. (A
//   machine may set OPENBLAS_CORETYPE=Haswell for every process, as the
//   shared test machine does; the suite keeps a caller's choice.)
//
// FAISS's process-wide search settings (threads, BLAS block) are chosen per
// peer by a sweep at creation (bench/peers/faiss_peers.cpp) and recorded in
// each cell's label.
#include <benchmark/benchmark.h>
#include <dlfcn.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

// OpenBLAS's description of itself (its build and the kernels it picked),
// or null when the BLAS is not OpenBLAS.
const char* openblas_config() {
  using Config = char* (*)();
  const auto config = reinterpret_cast<Config>(dlsym(RTLD_DEFAULT, "openblas_get_config"));
  return config != nullptr ? config() : nullptr;
}

bool wants_skylakex_kernels() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  const char* config = openblas_config();
  if (config == nullptr || std::getenv("OPENBLAS_CORETYPE") != nullptr) return false;
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
                      __builtin_cpu_supports("avx512cd");
  return avx512 && (std::strstr(config, " Haswell ") != nullptr || std::strstr(config, " Zen ") != nullptr);
#else
  return false;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  const bool set_policy = policy == nullptr;
  const bool set_coretype = wants_skylakex_kernels();
  if (set_policy || set_coretype) {
    if (set_policy) setenv("OMP_WAIT_POLICY", "passive", 1);
    if (set_coretype) setenv("OPENBLAS_CORETYPE", "SkylakeX", 1);
    execv("/proc/self/exe", argv);
    std::perror("mmvk_suite: cannot run itself again with its OpenMP and OpenBLAS settings; continuing without them");
  }
  benchmark::AddCustomContext("omp_wait_policy", policy != nullptr ? policy : "unset");
  const char* config = openblas_config();
  benchmark::AddCustomContext("blas", config != nullptr ? config : "not OpenBLAS");
  // The kernels chosen by OPENBLAS_CORETYPE (the caller's, or ours above),
  // or "unset": OpenBLAS's own pick (in `blas`).
  const char* coretype = std::getenv("OPENBLAS_CORETYPE");
  benchmark::AddCustomContext("openblas_coretype", coretype != nullptr ? coretype : "unset");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
