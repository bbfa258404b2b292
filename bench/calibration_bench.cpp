// Machine context for the benchmark suite's report (bench/report): what this
// CPU can do at most, measured, so that search figures can be stated as a
// fraction of the limit.
//   calibration/fma_peak/avx2     - one core, 8-lane FMA, 10 independent chains
//   calibration/fma_peak/avx512   - one core, 16-lane FMA (skipped without AVX-512F)
//   calibration/stream_read/threads:T - sequential read of a buffer far larger
//                                   than the last-level cache, summed in
//                                   registers; T = 1 and every core
//   calibration/vulkan_device     - the Vulkan device and driver, as the label
//
//   build/bench/mmvk_bench --benchmark_filter='^calibration/'
//
// Counters: flops/s (per core: one thread) and bytes/s (all threads of the run).
#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <thread>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define MMVK_BENCH_X86 1
#endif

#ifdef MMVK_HAS_VULKAN
#include "mmvk/vulkan/context.hpp"
#endif

namespace mmvk::bench {
namespace {

#ifdef MMVK_BENCH_X86
// Ten chains hide the FMA latency (4 cycles) behind two FMA pipes; the empty
// asm keeps the compiler from folding the loop.
constexpr int kChains = 10;

__attribute__((target("avx2,fma"))) float fma_loop_avx2(std::int64_t iterations) {
  __m256 acc[kChains];
  for (int i = 0; i < kChains; ++i) acc[i] = _mm256_set1_ps(float(i));
  const __m256 a = _mm256_set1_ps(0.999f), b = _mm256_set1_ps(0.001f);
  for (std::int64_t it = 0; it < iterations; ++it) {
    for (int i = 0; i < kChains; ++i) acc[i] = _mm256_fmadd_ps(acc[i], a, b);
    for (int i = 0; i < kChains; ++i) asm volatile("" : "+x"(acc[i]));
  }
  __m256 sum = acc[0];
  for (int i = 1; i < kChains; ++i) sum = _mm256_add_ps(sum, acc[i]);
  float lanes[8];
  _mm256_storeu_ps(lanes, sum);
  return lanes[0];
}

__attribute__((target("avx512f"))) float fma_loop_avx512(std::int64_t iterations) {
  __m512 acc[kChains];
  for (int i = 0; i < kChains; ++i) acc[i] = _mm512_set1_ps(float(i));
  const __m512 a = _mm512_set1_ps(0.999f), b = _mm512_set1_ps(0.001f);
  for (std::int64_t it = 0; it < iterations; ++it) {
    for (int i = 0; i < kChains; ++i) acc[i] = _mm512_fmadd_ps(acc[i], a, b);
    for (int i = 0; i < kChains; ++i) asm volatile("" : "+v"(acc[i]));
  }
  __m512 sum = acc[0];
  for (int i = 1; i < kChains; ++i) sum = _mm512_add_ps(sum, acc[i]);
  // Stored and read back rather than _mm512_reduce_add_ps, whose GCC 12
  // expansion trips -Wuninitialized.
  float lanes[16];
  _mm512_storeu_ps(lanes, sum);
  return lanes[0];
}

template <int Lanes>
void fma_peak(benchmark::State& state) {
  const bool supported = Lanes == 16 ? __builtin_cpu_supports("avx512f")
                                     : (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"));
  if (!supported) {
    state.SkipWithError(Lanes == 16 ? "no AVX-512F on this CPU" : "no AVX2 + FMA on this CPU");
    return;
  }
  constexpr std::int64_t kIterations = 1 << 20;
  for (auto _ : state) {
    benchmark::DoNotOptimize(Lanes == 16 ? fma_loop_avx512(kIterations) : fma_loop_avx2(kIterations));
  }
  // chains x lanes x 2 flops (multiply and add) per iteration.
  state.counters["flops/s"] =
      benchmark::Counter(double(kIterations) * kChains * Lanes * 2.0, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["lanes"] = Lanes;
}

// 512 MiB: 16x the last-level cache of the machines this runs on, so the
// read comes from memory, not cache.
constexpr std::size_t kStreamBytes = std::size_t(512) << 20;

const float* stream_buffer() {
  static const std::unique_ptr<float[]> buffer = [] {
    std::unique_ptr<float[]> b(new (std::nothrow) float[kStreamBytes / sizeof(float)]);
    // Touch every page so the timed loop measures reads, not page faults.
    if (b) std::memset(b.get(), 0, kStreamBytes);
    return b;
  }();
  return buffer.get();
}

__attribute__((target("avx2"))) float sum_floats(const float* data, std::size_t count) {
  __m256 acc[4] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
  for (std::size_t i = 0; i + 32 <= count; i += 32) {
    for (int j = 0; j < 4; ++j) acc[j] = _mm256_add_ps(acc[j], _mm256_loadu_ps(data + i + 8 * j));
  }
  const __m256 sum = _mm256_add_ps(_mm256_add_ps(acc[0], acc[1]), _mm256_add_ps(acc[2], acc[3]));
  float lanes[8];
  _mm256_storeu_ps(lanes, sum);
  return lanes[0];
}

void stream_read(benchmark::State& state) {
  const float* buffer = stream_buffer();
  if (buffer == nullptr || !__builtin_cpu_supports("avx2")) {
    state.SkipWithError(buffer == nullptr ? "cannot allocate the stream buffer" : "no AVX2 on this CPU");
    return;
  }
  // Each thread reads its own slice, so the threads together read the buffer once.
  const std::size_t floats = kStreamBytes / sizeof(float) / std::size_t(state.threads());
  const float* slice = buffer + floats * std::size_t(state.thread_index());
  for (auto _ : state) benchmark::DoNotOptimize(sum_floats(slice, floats));
  state.counters["bytes/s"] =
      benchmark::Counter(double(floats * sizeof(float)), benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK(fma_peak<8>)->Name("calibration/fma_peak/avx2")->UseRealTime();
BENCHMARK(fma_peak<16>)->Name("calibration/fma_peak/avx512")->UseRealTime();
// The name the first CPU search figures (bench/HISTORY.md) were measured
// under, kept so they stay comparable.
BENCHMARK(fma_peak<8>)->Name("machine/fma_peak_1thread")->UseRealTime();
const bool stream_registered = [] {
  auto* b = benchmark::RegisterBenchmark("calibration/stream_read", stream_read);
  b->UseRealTime()->Unit(benchmark::kMillisecond)->Threads(1);
  const int cores = int(std::thread::hardware_concurrency());
  if (cores > 1) b->Threads(cores);
  return true;
}();
#endif  // MMVK_BENCH_X86

#ifdef MMVK_HAS_VULKAN
// The device the Vulkan backends of this process pick (Context's default
// choice), with the driver's own name and version string, as the label.
void vulkan_device(benchmark::State& state) {
  Result<std::unique_ptr<vulkan::Context>> context = vulkan::Context::create();
  if (!context) {
    state.SkipWithError(context.message().c_str());
    return;
  }
  VkPhysicalDeviceDriverProperties driver{};
  driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
  VkPhysicalDeviceProperties2 properties{};
  properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  properties.pNext = &driver;
  vkGetPhysicalDeviceProperties2((*context)->physical_device(), &properties);
  for (auto _ : state) benchmark::DoNotOptimize(properties.properties.deviceID);
  state.SetLabel((*context)->device_name() + " | " + driver.driverName + " " + driver.driverInfo);
  state.counters["subgroup"] = (*context)->subgroup_size();
  state.counters["timestamps"] = (*context)->timestamp_valid_bits() > 0 ? 1 : 0;
}
BENCHMARK(vulkan_device)->Name("calibration/vulkan_device")->Iterations(1);
#endif

}  // namespace
}  // namespace mmvk::bench
