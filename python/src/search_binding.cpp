// mmvk.Search and mmvk.backends(): a backend made by name from the library's
// registry, searched with NumPy query batches, the GIL released meanwhile.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "errors.hpp"
#include "backends/host_backends.hpp"
#include "mmvk/search/backends.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/query/query_builder.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::python {

namespace py = pybind11;

namespace {

// A backend and everything it needs, in the order they must be destroyed
// last (the database, the pool, the table and the backends' Vulkan context
// outlive the backend).
class PySearch {
 public:
  PySearch(std::shared_ptr<Database> database, const std::string& backend, const py::object& device,
           const py::kwargs& options);

  py::tuple search(const py::object& queries, std::uint32_t k, const py::object& continuing,
                   const std::vector<std::string>& require, const std::vector<std::string>& exclude,
                   const py::object& weights, float continuing_bias, float continuing_multiplier,
                   std::uint32_t exclusion_window);

  // Seconds per call of `calls` backend searches of `queries` in a C++ loop:
  // the same call Search.search makes, without Python around it (the
  // benchmark's baseline, bench/python_overhead.py).
  double native_seconds(const py::object& queries, std::uint32_t k, std::uint32_t calls);

  std::string name() const { return std::string(backend_->name()); }
  const std::string& device() const { return device_; }
  const std::shared_ptr<Database>& database() const { return database_; }

 private:
  std::shared_ptr<Database> database_;
  std::unique_ptr<ThreadPool> pool_;
  std::optional<ClusterTable> table_;
  crowd::HostBackends backends_;
  std::unique_ptr<SearchBackend> backend_;
  std::string device_;
  // A backend is not thread-safe: two Python threads on one Search take turns.
  std::mutex mutex_;
};

// An option taken out of `options` (what is left is unknown), checked with
// its name in errors.
template <class T>
T option(py::dict& options, const char* name, T fallback) {
  if (!options.contains(name)) return fallback;
  const py::object given = options[name];
  PyDict_DelItemString(options.ptr(), name);
  if constexpr (std::is_same_v<T, bool>) {
    if (!py::isinstance<py::bool_>(given)) throw py::type_error(std::string(name) + ": expected True or False");
    return given.cast<bool>();
  } else {
    return integer_as<T>(given, name);
  }
}

// k before the results are allocated: it sizes them (the backends check it
// too, after the allocation).
void check_k(std::uint32_t k) {
  if (k < 1 || k > kMaxK) {
    throw py::value_error("k: expected 1 to " + std::to_string(kMaxK) + ", got " + std::to_string(k));
  }
}

// A continuing frame as the backends take it: -1 (any negative) none.
std::uint32_t continuing_frame(long long frame) {
  return frame < 0 ? kNoFrame : std::uint32_t(std::min<long long>(frame, kNoFrame - 1LL));
}

PySearch::PySearch(std::shared_ptr<Database> database, const std::string& backend, const py::object& device,
                   const py::kwargs& given)
    : database_(std::move(database)) {
  if (!database_) throw py::type_error("db: expected an mmvk.Database, got None");
  py::dict options = given.attr("copy")();  // known options are taken out of the copy
  const auto threads = option<unsigned>(options, "threads", 0);
  pool_ = take(ThreadPool::create(threads));
  BackendSpec spec;
  spec.name = backend;
  spec.pool = pool_.get();
  spec.nprobe = option<std::uint32_t>(options, "nprobe", spec.nprobe);
  spec.kmeans.clusters = option<std::uint32_t>(options, "kmeans_clusters", spec.kmeans.clusters);
  spec.kmeans.iterations = option<std::uint32_t>(options, "kmeans_iterations", spec.kmeans.iterations);
  spec.kmeans.seed = option<std::uint64_t>(options, "kmeans_seed", spec.kmeans.seed);
  crowd::DeviceSearchLimits limits;
  limits.max_batch = option<std::uint32_t>(options, "max_batch", limits.max_batch);
  limits.max_k = option<std::uint32_t>(options, "max_k", limits.max_k);
  limits.max_tile = option<std::uint32_t>(options, "max_tile", limits.max_tile);
  // Compiling every kernel variant up front costs seconds on lavapipe.
  limits.warm_up = option<bool>(options, "warm_up", false);
  if (options.contains("clusters")) {
    const std::filesystem::path path = to_path(options["clusters"], "clusters");
    PyDict_DelItemString(options.ptr(), "clusters");
    table_ = take(load_cluster_table(path), kind_for_input(path));
    spec.clusters = &*table_;
  }
  if (!options.empty()) {
    raise("unknown Search option '" + py::str((*options.begin()).first).cast<std::string>() +
          "' (known: threads, nprobe, clusters, kmeans_clusters, kmeans_iterations, kmeans_seed, max_batch, max_k, "
          "max_tile, warm_up)");
  }
  crowd::HostBackendOptions host;
  host.application_name = "mmvk (Python)";
  if (!device.is_none()) host.device = integer_as<std::uint32_t>(device, "device");
  host.device_option = "device";
  backends_ = crowd::HostBackends(std::move(host));
  Result<std::unique_ptr<SearchBackend>> made = make_error("");
  {
    py::gil_scoped_release released;  // k-means training and kernel compiles take a while
    made = backends_.make(spec, *database_, limits);
  }
  backend_ = take(std::move(made));
  device_ = backend_->device();
  // Set before the first Vulkan context (host/crowd/backends/driver_cache.hpp).
  if (const std::string& note = backends_.driver_cache_note(); !note.empty()) {
    if (PyErr_WarnEx(PyExc_RuntimeWarning, note.c_str(), 1) != 0) throw py::error_already_set();
  }
}

py::tuple PySearch::search(const py::object& queries, std::uint32_t k, const py::object& continuing,
                           const std::vector<std::string>& require, const std::vector<std::string>& exclude,
                           const py::object& weights, float continuing_bias, float continuing_multiplier,
                           std::uint32_t exclusion_window) {
  const Database& db = *database_;
  check_k(k);
  const FloatRows rows = float_rows(queries, db.dims(), "queries", false);
  const std::size_t batch = rows.rows;

  QueryParams base;
  base.continuing_bias = continuing_bias;
  base.continuing_multiplier = continuing_multiplier;
  base.exclusion_window = exclusion_window;
  if (!require.empty()) base.require_all = take(db.tag_mask(require));
  if (!exclude.empty()) base.exclude_any = take(db.tag_mask(exclude));
  if (!weights.is_none()) {
    const auto weight_dict = weights.cast<py::dict>();
    for (const auto& [channel, weight] : weight_dict) {
      if (!py::isinstance<py::str>(channel)) {
        throw py::type_error("weights: expected channel names (str) as keys, got " +
                             std::string(py::str(py::type::of(channel).attr("__name__"))));
      }
      const std::string name = channel.cast<std::string>();
      const float value = float_argument(weight, "weights['" + name + "']");
      check(set_channel_weight(db.schema(), base, name, value));
    }
  }
  // Per-query params only when a query differs from the defaults (an empty
  // span means default params for every query).
  std::vector<QueryParams> params;
  if (!continuing.is_none()) {
    // One frame for all: a Python int or a NumPy integer scalar (not an array).
    if (PyIndex_Check(continuing.ptr()) && !py::isinstance<py::array>(continuing)) {
      base.continuing_frame = continuing_frame(integer_as<long long>(continuing, "continuing"));
      params.assign(batch, base);
    } else {
      const auto frames = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(continuing);
      if (!frames || frames.ndim() != 1 || std::size_t(frames.shape(0)) != batch) {
        raise("continuing: expected None, a frame, or an integer array of shape (" + std::to_string(batch) +
              ",) (-1 = none)");
      }
      params.assign(batch, base);
      for (std::size_t b = 0; b < batch; ++b) {
        params[b].continuing_frame = continuing_frame(frames.at(b));
      }
    }
  } else if (!(base.require_all == 0 && base.exclude_any == 0 && base.continuing_bias == 0.0f &&
               base.continuing_multiplier == 1.0f && base.exclusion_window == 0 &&
               base.channel_weights == QueryParams::filled_weights())) {
    params.assign(batch, base);
  }

  std::vector<Match> out(batch * std::size_t(k));
  Status status;
  {
    py::gil_scoped_release released;
    std::lock_guard<std::mutex> lock(mutex_);
    status = backend_->search(QueryBatch{rows.values, params, batch}, k, out);
  }
  check(status);
  py::array_t<std::int64_t> frames({py::ssize_t(batch), py::ssize_t(k)});
  py::array_t<float> costs({py::ssize_t(batch), py::ssize_t(k)});
  std::int64_t* f = frames.mutable_data();
  float* c = costs.mutable_data();
  for (std::size_t i = 0; i < out.size(); ++i) {
    f[i] = out[i].frame == kNoFrame ? -1 : std::int64_t(out[i].frame);
    c[i] = out[i].cost;
  }
  return py::make_tuple(frames, costs);
}

double PySearch::native_seconds(const py::object& queries, std::uint32_t k, std::uint32_t calls) {
  check_k(k);
  const FloatRows rows = float_rows(queries, database_->dims(), "queries", false);
  std::vector<Match> out(rows.rows * std::size_t(k));
  const QueryBatch batch{rows.values, {}, rows.rows};
  Status status;
  double seconds = 0.0;
  {
    py::gil_scoped_release released;
    std::lock_guard<std::mutex> lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    for (std::uint32_t c = 0; c < calls && status.ok(); ++c) status = backend_->search(batch, k, out);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  check(status);
  return seconds / std::max<std::uint32_t>(calls, 1);
}

}  // namespace

void bind_search(py::module_& m) {
  m.def(
      "backends",
      []() {
        std::vector<std::string> names;
        const crowd::HostBackends listed;
        for (const BackendEntry& e : listed.registry().entries()) names.push_back(e.name);
        return names;
      },
      "The search backends by name: the CPU ones (reference, fast-brute, fast-box, clusters, clusters-nprobe) and, "
      "when mmvk was built with Vulkan, the vulkan-* ones.");

  py::class_<PySearch>(m, "Search",
                       "A search backend over a Database, made by name (mmvk.backends()). Search(db, backend='clusters', "
                       "device=None, **options); options: threads (CPU backends; 0 = all cores), nprobe, clusters (an "
                       ".mmkc file), kmeans_clusters, kmeans_iterations, kmeans_seed, max_batch, max_k, max_tile, "
                       "warm_up (Vulkan backends). device: a Vulkan device index.")
      .def(py::init([](std::shared_ptr<Database> db, const std::string& backend, const py::object& device,
                       const py::kwargs& options) { return std::make_unique<PySearch>(std::move(db), backend, device, options); }),
           py::arg("db"), py::arg("backend") = "clusters", py::arg("device") = py::none())
      .def("search", &PySearch::search, py::arg("queries"), py::arg("k") = 1, py::arg("continuing") = py::none(),
           py::arg("require") = std::vector<std::string>{}, py::arg("exclude") = std::vector<std::string>{},
           py::arg("weights") = py::none(), py::arg("continuing_bias") = 0.0f, py::arg("continuing_multiplier") = 1.0f,
           py::arg("exclusion_window") = 0u,
           "search(queries, k=1, continuing=None, require=(), exclude=(), weights=None, continuing_bias=0.0, "
           "continuing_multiplier=1.0, exclusion_window=0) -> (frames, costs)\n\n"
           "The best k frames of each query. queries: normalized features, float32 [B x dims] (Database.normalize "
           "makes them from raw values). continuing: None, one frame for every query, or int [B] (-1 = none). "
           "require / exclude: tag names. weights: {channel name: weight}. Returns frames int64 [B x k] (-1: no "
           "further candidate) and costs float32 [B x k] (inf there), best first; the semantics of docs/search.md, "
           "equal to `mmvk query`. The GIL is released while searching.")
      .def("_native_seconds", &PySearch::native_seconds, py::arg("queries"), py::arg("k") = 1, py::arg("calls") = 1,
           "Seconds per call of `calls` searches of `queries` (default params) made in a C++ loop: the same backend "
           "call as search() without Python around it. For bench/python_overhead.py.")
      .def_property_readonly("name", &PySearch::name, "The backend's name.")
      .def_property_readonly("device", &PySearch::device, "Where it runs, as the backend reports it (the same text as mmvk.Crowd.device and `mmvk query`): 'cpu, N threads', or the Vulkan device's name, index and type.")
      .def_property_readonly("database", &PySearch::database, "The Database searched.")
      .def("__repr__", [](const PySearch& s) { return "<mmvk.Search: " + s.name() + " on " + s.device() + ">"; });
}

}  // namespace mmvk::python
