// mmvk_faiss_plain: FAISS's IndexFlatL2 the way its own examples use it,
// outside the suite's machinery, to check the suite's faiss-flat figures
// (the two must agree within 20%) and to sweep the settings that decide
// FAISS flat's speed on a machine:
//   - OpenMP threads (omp_set_num_threads: 1 ... all cores),
//   - FAISS's BLAS block over the database (distance_compute_blas_database_bs,
//     default 1024 rows): each block is one sgemm and one OpenMP reduction,
//     so small blocks multiply the thread wake-ups,
//   - from the environment, per process: OMP_WAIT_POLICY (passive, active)
//     and the BLAS library (LD_LIBRARY_PATH to another libblas.so.3).
//
//   build/bench/mmvk_faiss_plain DB.mmdb [--batch B] [--repeats R] [--threads 1,2] [--db-bs 1024,16384]
//   build/bench/mmvk_faiss_plain build/bench-data/volume-default27-all.mmdb --batch 1024
//
// The database is the suite's (bench/bench_data.hpp: every frame a
// candidate); the queries are B rows spread over it, each moved by a fixed
// offset (so no query is a row). Prints one line per setting: the median
// of R searches of the whole batch, as µs per query, with the BLAS library
// and the OpenMP wait policy in force.
#include <dlfcn.h>
#include <faiss/IndexFlat.h>
#include <faiss/utils/distances.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "mmvk/database/database_io.hpp"

namespace {

std::vector<int> int_list(const std::string& text) {
  std::vector<int> values;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) values.push_back(std::atoi(item.c_str()));
  return values;
}

// OpenBLAS's own description (its build and the core it picked), when the
// BLAS loaded is OpenBLAS.
std::string blas_name() {
  using ConfigFn = char* (*)();
  if (auto config = reinterpret_cast<ConfigFn>(dlsym(RTLD_DEFAULT, "openblas_get_config"))) return config();
  return "not OpenBLAS (reference BLAS?)";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: mmvk_faiss_plain DB.mmdb [--batch B] [--repeats R] [--threads 1,2] [--db-bs 1024,16384]\n");
    return 2;
  }
  std::size_t batch = 1024;
  int repeats = 5;
  std::vector<int> threads = {omp_get_max_threads()};
  std::vector<int> db_bs = {faiss::distance_compute_blas_database_bs};
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--batch") batch = std::strtoul(argv[i + 1], nullptr, 10);
    else if (flag == "--repeats") repeats = std::atoi(argv[i + 1]);
    else if (flag == "--threads") threads = int_list(argv[i + 1]);
    else if (flag == "--db-bs") db_bs = int_list(argv[i + 1]);
    else {
      std::fprintf(stderr, "mmvk_faiss_plain: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  mmvk::Result<mmvk::Database> db = mmvk::load_database(argv[1]);
  if (!db) {
    std::fprintf(stderr, "mmvk_faiss_plain: %s\n", db.message().c_str());
    return 1;
  }
  const std::size_t n = db->frame_count();
  const std::size_t d = db->dims();
  const float* x = db->features().data();
  std::vector<float> queries(batch * d);
  for (std::size_t q = 0; q < batch; ++q) {
    const float* row = x + (q * (n / batch)) * d;
    for (std::size_t j = 0; j < d; ++j) queries[q * d + j] = row[j] + 0.05f * float((q + j) % 7) - 0.15f;
  }
  faiss::IndexFlatL2 index(static_cast<faiss::Index::idx_t>(d));
  index.add(static_cast<faiss::Index::idx_t>(n), x);
  std::vector<float> distances(batch);
  std::vector<faiss::Index::idx_t> labels(batch);
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  std::printf("# N = %zu, dims = %zu, B = %zu, OMP_WAIT_POLICY = %s, BLAS: %s\n", n, d, batch,
              policy ? policy : "unset", blas_name().c_str());
  for (const int t : threads) {
    omp_set_num_threads(t);
    for (const int bs : db_bs) {
      faiss::distance_compute_blas_database_bs = bs;
      index.search(static_cast<faiss::Index::idx_t>(batch), queries.data(), 1, distances.data(), labels.data());  // warm-up
      std::vector<double> us;
      for (int r = 0; r < repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        index.search(static_cast<faiss::Index::idx_t>(batch), queries.data(), 1, distances.data(), labels.data());
        us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() /
                     double(batch));
      }
      std::sort(us.begin(), us.end());
      std::printf("threads %d  db_bs %6d  %8.1f us/query (median of %d; min %.1f, max %.1f)\n", t, bs,
                  us[us.size() / 2], repeats, us.front(), us.back());
      std::fflush(stdout);
    }
  }
  return 0;
}
