// The backend registry (mmvk/search/backends.hpp): every CPU name makes a backend
// whose name() is that name, an unknown name lists the known ones, and the
// spec's mistakes (no pool, nprobe 0, a table of another database, a
// duplicate entry) are errors, not crashes; each backend reports its device.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>
#include <string>

#include "mmvk/search/backends.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "support/cluster_table_cache.hpp"
#include "support/search_test_data.hpp"

namespace mmvk::test {
namespace {

TEST(BackendRegistry, EveryCpuNameRoundTripsThroughName) {
  const Database db = synthetic_database({.frames = 600, .seed = 3});
  ThreadPool pool(2);
  const BackendRegistry registry = cpu_backends();
  const std::set<std::string> expected = {"reference", "fast-brute", "fast-box", "clusters", "clusters-nprobe"};
  std::set<std::string> names;
  for (const BackendEntry& entry : registry.entries()) {
    SCOPED_TRACE(entry.name);
    names.insert(entry.name);
    EXPECT_FALSE(entry.description.empty());
    EXPECT_EQ(entry.uses_cluster_table, entry.name.starts_with("clusters"));
    // Cluster backends train their own table here (no BackendSpec::clusters).
    BackendSpec spec{.name = entry.name, .pool = &pool};
    spec.kmeans.iterations = 3;
    Result<std::unique_ptr<SearchBackend>> backend = registry.make(spec, db);
    ASSERT_TRUE(backend.ok()) << backend.message();
    EXPECT_EQ((*backend)->name(), entry.name);
    EXPECT_EQ(&(*backend)->database(), &db);
    // The free function makes the same kinds.
    Result<std::unique_ptr<SearchBackend>> again = make_backend(spec, db);
    ASSERT_TRUE(again.ok()) << again.message();
    EXPECT_EQ((*again)->name(), entry.name);
  }
  EXPECT_EQ(names, expected);
  EXPECT_EQ(registry.names(), "reference, fast-brute, fast-box, clusters, clusters-nprobe");
  // help(): one padded line per entry, in order.
  const std::string help = registry.help("  ");
  EXPECT_EQ(std::count(help.begin(), help.end(), '\n'), 5);
  EXPECT_EQ(help.find("  reference        " + registry.find("reference")->description + "\n"), 0u) << help;
  EXPECT_NE(help.find("\n  clusters-nprobe  "), std::string::npos) << help;
}

// Each backend says where it runs itself: the reference on one thread, the
// others on their pool's threads.
TEST(BackendRegistry, EveryCpuBackendReportsItsOwnDevice) {
  const Database db = synthetic_database({.frames = 300, .seed = 5});
  ThreadPool one(1);
  ThreadPool three(3);
  const BackendRegistry registry = cpu_backends();
  for (const BackendEntry& entry : registry.entries()) {
    SCOPED_TRACE(entry.name);
    for (ThreadPool* pool : {&one, &three}) {
      BackendSpec spec{.name = entry.name, .pool = pool};
      spec.kmeans.iterations = 3;
      Result<std::unique_ptr<SearchBackend>> backend = registry.make(spec, db);
      ASSERT_TRUE(backend.ok()) << backend.message();
      const bool single = entry.name == "reference" || pool == &one;
      EXPECT_EQ((*backend)->device(), single ? "cpu, 1 thread" : "cpu, 3 threads");
    }
  }
  EXPECT_EQ(cpu_device_text(8), "cpu, 8 threads");
}

TEST(BackendRegistry, UnknownNameListsTheKnownOnes) {
  const Database db = synthetic_database({.frames = 200, .seed = 4});
  const BackendRegistry registry = cpu_backends();
  EXPECT_EQ(registry.find("fast"), nullptr);
  for (const char* name : {"fast", "nprobe", "", "Reference"}) {
    Result<std::unique_ptr<SearchBackend>> backend = registry.make(BackendSpec{.name = name}, db);
    ASSERT_FALSE(backend.ok()) << name;
    EXPECT_NE(backend.message().find("unknown backend '" + std::string(name) + "'"), std::string::npos)
        << backend.message();
    for (const BackendEntry& entry : registry.entries()) {
      EXPECT_NE(backend.message().find(entry.name), std::string::npos) << backend.message();
    }
  }
}

TEST(BackendRegistry, SpecMistakesAreErrors) {
  const Database db = synthetic_database({.frames = 400, .seed = 5});
  const Database other = synthetic_database({.frames = 400, .seed = 6});
  ClusterTableCache tables;
  Result<const ClusterTable*> table = tables.table_for(db);
  ASSERT_TRUE(table.ok()) << table.message();
  const BackendRegistry registry = cpu_backends();

  Result<std::unique_ptr<SearchBackend>> no_pool = registry.make(BackendSpec{.name = "fast-box"}, db);
  ASSERT_FALSE(no_pool.ok());
  EXPECT_NE(no_pool.message().find("pool"), std::string::npos) << no_pool.message();

  BackendSpec zero{.name = "clusters-nprobe", .pool = &tables.pool, .clusters = *table};
  zero.nprobe = 0;
  Result<std::unique_ptr<SearchBackend>> zero_probe = registry.make(zero, db);
  ASSERT_FALSE(zero_probe.ok());
  EXPECT_NE(zero_probe.message().find("nprobe"), std::string::npos) << zero_probe.message();

  for (const char* name : {"clusters", "clusters-nprobe"}) {
    Result<std::unique_ptr<SearchBackend>> mismatched =
        registry.make(BackendSpec{.name = name, .pool = &tables.pool, .clusters = *table}, other);
    ASSERT_FALSE(mismatched.ok()) << name;
    EXPECT_NE(mismatched.message().find("cluster table"), std::string::npos) << mismatched.message();
  }

  // A loaded table of this database is used as given.
  BackendSpec loaded{.name = "clusters", .pool = &tables.pool, .clusters = *table};
  Result<std::unique_ptr<SearchBackend>> made = registry.make(loaded, db);
  ASSERT_TRUE(made.ok()) << made.message();
  EXPECT_EQ(static_cast<const ClusterSearch&>(**made).cluster_count(), (*table)->cluster_count);
}

TEST(BackendRegistry, AddRefusesDuplicatesAndEmptyEntries) {
  BackendRegistry registry = cpu_backends();
  const std::size_t count = registry.entries().size();
  const BackendFactory reference = registry.find("reference")->make;
  EXPECT_FALSE(registry.add({"reference", "again", reference}).ok());
  EXPECT_FALSE(registry.add({"", "no name", reference}).ok());
  EXPECT_FALSE(registry.add({"no-factory", "no factory", {}}).ok());
  EXPECT_EQ(registry.entries().size(), count);
  ASSERT_TRUE(registry.add({"reference-2", "the reference under another name", reference}).ok());
  EXPECT_NE(registry.find("reference-2"), nullptr);
  EXPECT_NE(registry.names().find("reference-2"), std::string::npos);
}

}  // namespace
}  // namespace mmvk::test
