// The per-tick path allocates nothing (issue 30): after a warm-up, a
// controller tick on the deferred search (validation included) and a
// search's own checks make no heap allocation. This binary replaces the
// global operator new to count them; before the fix, validate_queries built
// one std::string per query of every search.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/search/backends.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "support/test_data.hpp"

namespace {

std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_allocations{0};

void* counted_allocation(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

// Allocations made by `work` on any thread.
template <class Work>
std::size_t allocations_during(Work&& work) {
  g_allocations = 0;
  g_counting = true;
  work();
  g_counting = false;
  return g_allocations.load();
}

}  // namespace

void* operator new(std::size_t size) { return counted_allocation(size); }
void* operator new[](std::size_t size) { return counted_allocation(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace mmvk {
namespace {

// The crowd's shipped CMU subject 131 walks: an animated database small
// enough to build in well under a second.
Database shipped_walks() {
  const auto manifest =
      load_manifest(test::test_source_dir().parent_path() / "host" / "crowd" / "data" / "cmu131" / "manifest.json");
  EXPECT_TRUE(manifest.ok()) << manifest.message();
  Result<Database> db = build_database(*manifest);
  EXPECT_TRUE(db.ok()) << db.message();
  return std::move(db.value());
}

TEST(TickAllocationCounter, TheCounterSeesAnAllocation) {
  // The test can fail: a std::string beyond the small-string buffer is counted.
  const std::size_t counted = allocations_during([] {
    std::string text(100, 'x');
    ASSERT_EQ(text.size(), 100u);
  });
  EXPECT_EQ(counted, 1u);
}

TEST(TickAllocationCounter, ValidatingASearchAllocatesNothing) {
  const Database db = shipped_walks();
  constexpr std::size_t kQueries = 64;
  std::vector<float> features(kQueries * db.dims());
  for (std::size_t q = 0; q < kQueries; ++q) {
    const auto row = db.row(std::uint32_t(q * 13 % db.frame_count()));
    std::copy(row.begin(), row.end(), features.begin() + std::ptrdiff_t(q * db.dims()));
  }
  std::vector<QueryParams> params(kQueries);
  for (std::size_t q = 0; q < kQueries; ++q) params[q].continuing_frame = std::uint32_t(q);
  std::vector<Match> out(kQueries);
  const QueryBatch batch{features, params, kQueries};
  const std::size_t counted = allocations_during([&] {
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(validate_search(db, batch, 1, out).ok());
  });
  EXPECT_EQ(counted, 0u) << "validate_search allocated on the per-query path";
}

// The CPU backends --backend auto picks (crowd_backend.hpp).
class TickAllocation : public ::testing::TestWithParam<const char*> {};

TEST_P(TickAllocation, AControllerTickAfterWarmUpAllocatesNothing) {
  const Database db = shipped_walks();
  ThreadPool pool(2);  // the workers' hand-over too
  BackendSpec spec;
  spec.name = GetParam();
  spec.pool = &pool;
  Result<std::unique_ptr<SearchBackend>> backend = cpu_backends().make(spec, db);
  ASSERT_TRUE(backend.ok()) << backend.message();
  constexpr std::uint32_t kCharacters = 32;
  const std::unique_ptr<AsyncSearch> search = (*backend)->make_async(kCharacters);
  ControllerParams params;
  params.search_interval = 0.05f;  // several searches every tick
  Result<CrowdController> controller = CrowdController::create(db, kCharacters, params);
  ASSERT_TRUE(controller.ok()) << controller.message();
  for (std::uint32_t b = 0; b < kCharacters; ++b) {
    ASSERT_TRUE(controller->place(b, glm::vec3(3.0f * float(b), 0.0f, 0.0f), 0.2f * float(b)).ok());
  }
  std::vector<glm::vec3> desired(kCharacters, glm::vec3(0.0f, 0.0f, 1.2f));
  const float dt = 1.0f / 30.0f;
  // Warm-up: every buffer grows to its size.
  for (int t = 0; t < 30; ++t) ASSERT_TRUE(controller->tick(dt, CrowdInput{desired, {}}, *search, pool).ok());
  std::uint64_t searches = 0;
  const std::size_t counted = allocations_during([&] {
    for (int t = 0; t < 30; ++t) {
      ASSERT_TRUE(controller->tick(dt, CrowdInput{desired, {}}, *search, pool).ok());
      searches += controller->last_tick().searches;
    }
  });
  EXPECT_GT(searches, 0u) << "the ticks searched";
  EXPECT_EQ(counted, 0u) << "allocations in 30 controller ticks after warm-up on " << GetParam();
}

INSTANTIATE_TEST_SUITE_P(CpuBackends, TickAllocation, ::testing::Values("fast-box", "clusters"));

}  // namespace
}  // namespace mmvk
