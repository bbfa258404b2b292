// mmvk.Crowd: the crowd host's CrowdSession (host/crowd/crowd_session.hpp)
// stepped from Python, by its own steering or by another simulator's.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "crowd_defaults.hpp"
#include "crowd_limits.hpp"
#include "crowd_session.hpp"
#include "errors.hpp"
#include "mmvk/number_text.hpp"
#include "mmvk/steering_input.hpp"
#include "scenario.hpp"
#include "summary.hpp"

namespace mmvk::python {

namespace py = pybind11;
using crowd::CrowdSession;
using crowd::CrowdSessionOptions;

namespace {

// A session reached through its object's lock, held while this lives: a
// property read or write_html from one thread while another steps waits
// its turn instead of reading a session in the middle of a tick.
template <class Session>
class HeldSession {
 public:
  HeldSession(std::unique_lock<std::mutex> lock, Session& session) : lock_(std::move(lock)), session_(session) {}
  Session* operator->() const { return &session_; }

 private:
  std::unique_lock<std::mutex> lock_;
  Session& session_;
};

// How long a run() steps with the GIL released before it takes it back to
// check for signals, so Ctrl-C stops a long run with KeyboardInterrupt.
constexpr auto kSignalCheckInterval = std::chrono::milliseconds(100);

class PyCrowd {
 public:
  PyCrowd(std::shared_ptr<Database> database, const CrowdSessionOptions& options) : database_(std::move(database)) {
    if (!database_) throw py::type_error("db: expected an mmvk.Database, got None");
    Result<std::unique_ptr<CrowdSession>> made = make_error("");
    {
      py::gil_scoped_release released;
      made = CrowdSession::create(*database_, options);
    }
    session_ = take(std::move(made));
    agents_ = session_->agents();
    velocity_.resize(agents_);
    next_.resize(agents_);
    positions_.emplace(agents_);
  }

  void step(const py::object& desired_velocity, const py::object& desired_facing) {
    const auto held = lock();
    if (desired_velocity.is_none()) {
      if (!desired_facing.is_none()) raise("desired_facing: given without desired_velocity");
      Status status;
      {
        py::gil_scoped_release released;
        status = session_->step();
      }
      check(status);
      return;
    }
    read_xz(desired_velocity, "desired_velocity", velocity_);
    steer(desired_facing);
  }

  // Velocities from the host's positions at the end of this tick
  // (PositionSteering, mmvk/steering_input.hpp).
  void step_toward(const py::object& next_positions, const py::object& desired_facing) {
    const auto held = lock();
    read_xz(next_positions, "next_positions", next_);
    check(positions_->velocities(session_->controller().simulation(), next_, float(session_->dt()), velocity_));
    steer(desired_facing);
  }

  void run(double seconds) {
    check(crowd::check_tick_count(seconds, session_->rate_hz(), 0, "seconds", crowd::SettingNames::Keywords));
    const auto ticks = std::uint64_t(std::llround(seconds / session_->dt()));
    const auto held = lock();
    Status status;
    for (std::uint64_t t = 0; t < ticks && status.ok();) {
      {
        py::gil_scoped_release released;
        const auto until = std::chrono::steady_clock::now() + kSignalCheckInterval;
        do {
          status = session_->step();
          ++t;
        } while (t < ticks && status.ok() && std::chrono::steady_clock::now() < until);
      }
      // Ctrl-C (or any handler that raises) ends the run between ticks.
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    check(status);
  }

  void place(std::uint32_t index, float x, float z, float yaw, std::uint32_t frame) {
    const auto held = lock();
    check(session_->place(index, x, z, yaw, frame));
    positions_->reset();  // a teleport is no motion of the host's
  }

  HeldSession<const CrowdSession> session() const { return {lock(), *session_}; }
  HeldSession<CrowdSession> session() { return {lock(), *session_}; }
  std::uint32_t agents() const { return agents_; }

 private:
  // The object's lock. Taken without the GIL when another thread holds it:
  // that thread may need the GIL to finish (a run checks for signals).
  std::unique_lock<std::mutex> lock() const {
    std::unique_lock<std::mutex> held(mutex_, std::try_to_lock);
    if (!held.owns_lock()) {
      py::gil_scoped_release released;
      held.lock();
    }
    return held;
  }

  // (x, z) rows, or (x, y, z) with y ignored: [agents x 2|3] float32 into out.
  void read_xz(const py::object& value, const char* what, std::vector<glm::vec3>& out) const {
    const auto a = py::reinterpret_borrow<py::array>(value);
    const std::size_t cols = py::isinstance<py::array>(value) && a.ndim() == 2 && a.shape(1) == 3 ? 3 : 2;
    const FloatRows rows = float_rows(value, cols, what, false);
    if (rows.rows != agents_) {
      raise(std::string(what) + ": " + std::to_string(rows.rows) + " rows for " + std::to_string(agents_) + " agents");
    }
    for (std::size_t b = 0; b < agents_; ++b) {
      out[b] = glm::vec3(rows.values[b * cols], 0.0f, rows.values[b * cols + cols - 1]);
    }
  }

  // One tick on velocity_, facing `desired_facing` (None: the velocity).
  void steer(const py::object& desired_facing) {
    py::array keep;
    std::span<const float> yaw;
    if (!desired_facing.is_none()) yaw = float_vector(desired_facing, agents_, "desired_facing", keep);
    Status status;
    {
      py::gil_scoped_release released;
      status = session_->step(velocity_, yaw);
    }
    check(status);
  }

  std::shared_ptr<Database> database_;  // outlives the session
  std::unique_ptr<CrowdSession> session_;
  std::uint32_t agents_ = 0;
  std::vector<glm::vec3> velocity_, next_;  // [agents]
  std::optional<PositionSteering> positions_;  // step_toward's
  // One call at a time: a session is not thread-safe, and two threads
  // stepping, or one reading while another steps, corrupted it.
  mutable std::mutex mutex_;
};

// A copy of `values` ([n x 3] floats as glm::vec3) as float32 [n x 3].
py::array vec3_array(std::span<const glm::vec3> values, std::vector<py::ssize_t> shape) {
  py::array_t<float> out(shape);
  std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(glm::vec3));
  return out;
}

template <class T>
py::array copy_array(std::span<const T> values, std::vector<py::ssize_t> shape) {
  py::array_t<T> out(shape);
  std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
  return out;
}

crowd::Scenario scenario_of(const py::object& scenario) {
  if (py::isinstance<py::dict>(scenario)) {
    const std::string text = py::str(py::module_::import("json").attr("dumps")(scenario)).cast<std::string>();
    return take(crowd::parse_scenario_json(text, "the scenario dict"));
  }
  const std::filesystem::path path = to_path(scenario, "scenario");
  return take(crowd::load_scenario(path), kind_for_input(path));
}

// Crowd(db, ...): the options of `mmvk crowd`, with its defaults.
void add_construction(py::class_<PyCrowd>& crowd) {
  static const crowd::CrowdSettings kDefaults;
  crowd
      .def(py::init([](std::shared_ptr<Database> db, const py::object& agents, const std::string& backend,
                       double rate, std::uint64_t seed, const py::object& device, const py::object& scenario,
                       double search_interval, bool foot_ik, bool record, const std::string& title,
                       const py::object& correction_half_life, bool speed_from_animation) {
             CrowdSessionOptions options;
             options.backend = backend;
             options.rate_hz = rate;
             options.seed = seed;
             options.search_interval_s = search_interval;
             options.foot_ik = foot_ik;
             options.speed_from_animation = speed_from_animation;
             options.record = record;
             options.title = title;
             if (!device.is_none()) options.device = device.cast<std::uint32_t>();
             if (!correction_half_life.is_none()) options.correction_half_life = correction_half_life.cast<float>();
             if (!scenario.is_none()) options.scenario = scenario_of(scenario);
             if (!agents.is_none()) {
               // Checked as given, before the session checks the rest (CrowdSession::create).
               const long long n = agents.cast<long long>();
               check(crowd::check_agent_count(double(n), crowd::SettingNames::Keywords));
               options.agents = std::uint64_t(n);
             }
             return std::make_unique<PyCrowd>(std::move(db), options);
           }),
           py::arg("db"), py::arg("agents") = py::none(), py::arg("backend") = kDefaults.backend,
           py::arg("rate") = kDefaults.rate_hz, py::arg("seed") = kDefaults.seed, py::arg("device") = py::none(),
           py::arg("scenario") = py::none(), py::arg("search_interval") = kDefaults.search_interval_s,
           py::arg("foot_ik") = kDefaults.foot_ik, py::arg("record") = false,
           py::arg("title") = "", py::arg("correction_half_life") = py::none(),
           py::arg("speed_from_animation") = kDefaults.speed_from_animation);
}

// The ticks: the crowd's own steering, or another simulator's.
void add_stepping(py::class_<PyCrowd>& crowd) {
  crowd
      .def("step", &PyCrowd::step, py::arg("desired_velocity") = py::none(), py::arg("desired_facing") = py::none(),
           "step() -> None; step(desired_velocity, desired_facing=None) -> None\n\n"
           "One tick of 1/rate seconds. Without arguments the crowd's own steering seeks each character's goals. "
           "With desired_velocity (float32 [agents x 2] (x, z) or [agents x 3] (x, y, z), world m/s, y ignored) "
           "and optionally desired_facing (float32 [agents], yaw in radians, 0 faces +Z; None: face the velocity), "
           "another simulator steers. The GIL is released during the tick.")
      .def("step_toward", &PyCrowd::step_toward, py::arg("next_positions"), py::arg("desired_facing") = py::none(),
           "One tick toward the host's positions at the end of the tick: float32 [agents x 2] (x, z) or [agents x 3], "
           "metres. The desired velocity is the host's own motion plus a correction of the gap over 0.2 s "
           "(mmvk/steering_input.hpp: PositionSteering). desired_facing as for step().")
      .def("run", &PyCrowd::run, py::arg("seconds"),
           "Steps the crowd's own steering for `seconds` of simulated time (rounded to whole ticks), GIL released.")
      .def(
          "place",
          [](PyCrowd& c, std::uint32_t index, float x, float z, float yaw, std::uint32_t frame) {
            c.place(index, x, z, yaw, frame);
          },
          py::arg("index"), py::arg("x"), py::arg("z"), py::arg("yaw") = 0.0f, py::arg("frame") = 0,
          "Places character `index` at (x, z) metres facing `yaw` radians, playing database frame `frame`; its "
          "next tick searches.");
}

// The run's settings and the data's speeds.
void add_settings(py::class_<PyCrowd>& crowd) {
  crowd
      .def_property_readonly("agents", &PyCrowd::agents, "The number of characters.")
      .def_property_readonly("rate", [](const PyCrowd& c) { return 1.0 / c.session()->dt(); }, "Ticks per second.")
      .def_property_readonly("dt", [](const PyCrowd& c) { return c.session()->dt(); }, "Seconds per tick.")
      .def_property_readonly("ticks", [](const PyCrowd& c) { return c.session()->ticks(); }, "Ticks stepped so far.")
      .def_property_readonly("time",
                             [](const PyCrowd& c) {
                               const auto session = c.session();  // one lock for both reads
                               return double(session->ticks()) * session->dt();
                             },
                             "Simulated seconds so far.")
      .def_property_readonly("device", [](const PyCrowd& c) { return c.session()->device(); }, "Where the search runs.")
      .def_property_readonly("walk_speed", [](const PyCrowd& c) { return c.session()->speeds().walk_mps; },
                             "The database's typical walking speed, m/s.")
      .def_property_readonly(
          "run_speed",
          [](const PyCrowd& c) -> py::object {
            const auto session = c.session();
            const auto& s = session->speeds();
            return s.has_run ? py::object(py::float_(s.run_mps)) : py::none();
          },
          "The database's typical running speed, m/s, or None when the data has no run.")
      .def_property_readonly(
          "goals",
          [](const PyCrowd& c) {
            std::vector<std::vector<std::array<float, 2>>> goals;
            const auto session = c.session();
            for (const auto& plan : session->scenario().agents) goals.push_back(plan.goals);
            return goals;
          },
          "Each character's goal points [(x, z), ...] (its own steering visits them in turn).");
}

// Each character's state after the last step, as NumPy arrays (copies).
void add_state_arrays(py::class_<PyCrowd>& crowd) {
  crowd
      .def_property_readonly(
          "root_positions",
          [](const PyCrowd& c) {
            return vec3_array(c.session()->controller().root_positions(), {py::ssize_t(c.agents()), 3});
          },
          "Each character's root (as displayed), float32 [agents x 3], metres, y = 0. Arrays are copies.")
      .def_property_readonly(
          "root_yaws",
          [](const PyCrowd& c) { return copy_array(c.session()->controller().root_yaws(), {py::ssize_t(c.agents())}); },
          "Each character's facing, float32 [agents], radians about +Y (0 faces +Z; facing = (sin, cos)).")
      .def_property_readonly(
          "simulated_positions",
          [](const PyCrowd& c) {
            const auto session = c.session();
            const auto sim = session->controller().simulation();
            py::array_t<float> out({py::ssize_t(c.agents()), py::ssize_t(3)});
            float* o = out.mutable_data();
            for (std::size_t b = 0; b < sim.size(); ++b) {
              o[3 * b] = sim[b].position.x, o[3 * b + 1] = sim[b].position.y, o[3 * b + 2] = sim[b].position.z;
            }
            return out;
          },
          "Each character's simulated root (the spring that follows the desired velocity), float32 [agents x 3].")
      .def_property_readonly(
          "frames",
          [](const PyCrowd& c) { return copy_array(c.session()->controller().frames(), {py::ssize_t(c.agents())}); },
          "The database frame each character plays, uint32 [agents].")
      .def_property_readonly(
          "contacts",
          [](const PyCrowd& c) { return copy_array(c.session()->controller().contacts(), {py::ssize_t(c.agents())}); },
          "Foot contact bits of each character's frame, uint8 [agents] (Animation.contacts).")
      .def_property_readonly(
          "foot_locked",
          [](const PyCrowd& c) {
            return copy_array(c.session()->controller().foot_locked(), {py::ssize_t(c.agents()), 2});
          },
          "1 while a foot (left, right) is held where it was planted, uint8 [agents x 2].")
      .def_property_readonly(
          "joint_positions",
          [](const PyCrowd& c) {
            const auto session = c.session();
            const auto world = session->world_positions();
            const auto joints = py::ssize_t(world.size() / std::max<std::size_t>(c.agents(), 1));
            return vec3_array(world, {py::ssize_t(c.agents()), joints, 3});
          },
          "The displayed global joint positions after the last step (foot IK included), float32 [agents x joints "
          "x 3], metres.");
}

// One value per character from the controller, copied: `name`, [agents].
template <class T>
void add_per_character(py::class_<PyCrowd>& crowd, const char* name,
                       std::span<const T> (CrowdController::*values)() const, const char* doc) {
  crowd.def_property_readonly(
      name,
      [values](const PyCrowd& c) {
        const auto session = c.session();
        return copy_array((session->controller().*values)(), {py::ssize_t(c.agents())});
      },
      doc);
}

// Speed from the animation after the last step: the play rates, stride
// scales and root corrections (the glide).
void add_speed_arrays(py::class_<PyCrowd>& crowd) {
  add_per_character(crowd, "play_rates", &CrowdController::play_rates,
                    "The rate each character played its clip at in the last step (clip seconds per second), "
                    "float32 [agents].");
  add_per_character(crowd, "stride_scales", &CrowdController::stride_scales,
                    "The scale of each character's root motion in the last step, float32 [agents].");
  crowd.def_property_readonly(
      "root_corrections",
      [](const PyCrowd& c) {
        const auto session = c.session();
        return vec3_array(session->controller().root_corrections(), {py::ssize_t(c.agents()), 3});
      },
      "The root correction of the last step (the glide), float32 [agents x 3], world metres, y = 0: the shown root "
      "moved by its animation's root motion plus this.");
}

// The summary, the viewer page and the repr.
void add_outputs(py::class_<PyCrowd>& crowd) {
  crowd
      .def(
          "summary",
          [](const PyCrowd& c) {
            const std::string json = crowd::summary_to_json(c.session()->summary());
            return py::module_::import("json").attr("loads")(json);
          },
          "The run so far as a dict: the figures of `mmvk crowd --summary` (trajectory_error_m_1s, "
          "foot_sliding_cm_s, search_ms_p50, chosen_frames_hash, ...; README).")
      .def(
          "write_html",
          [](PyCrowd& c, const py::object& path) {
            const std::filesystem::path p = to_path(path, "path");
            auto session = c.session();
            Result<std::size_t> written = make_error("");
            {
              py::gil_scoped_release released;
              written = session->write_html(p);
            }
            return take(std::move(written), ErrorKind::OS);
          },
          py::arg("path"),
          "Writes the viewer page (one self-contained HTML file) of the steps so far; needs record=True. The "
          "recording ends at the first call and is kept: a failed write can be retried, and a later call writes the same "
          "page. Returns the bytes written.")
      .def("__repr__", [](const PyCrowd& c) {
        const std::uint64_t ticks = c.session()->ticks();
        return "<mmvk.Crowd: " + std::to_string(c.agents()) + " agents, " + std::to_string(ticks) +
               " ticks>";
      });;
}

// The class's docstring, its bounds from the crowd's limits (crowd_limits.hpp).
const char* crowd_doc() {
  static const std::string doc =
      "Motion-matched characters stepped from Python, as `mmvk crowd` runs them: the same controller, search and "
      "figures and defaults. Crowd(db, agents=None, backend='auto', rate=30.0, seed=1, device=None, scenario=None, "
      "search_interval=0.1, foot_ik=True, record=False, title='', correction_half_life=None, "
      "speed_from_animation=True). agents: the number of "
      "characters (1 to " + std::to_string(crowd::kMaxAgents) + "), drawn with goals from seed (default " +
      std::to_string(crowd::kDefaultAgents) + "), or scenario: a scenario JSON file or "
      "dict (starts, goals, speeds, tags; `mmvk crowd --scenario`), which sets the count. backend 'auto': a Vulkan "
      "backend on a GPU, else the fastest CPU backend. rate: " + number_text(crowd::kMinRateHz) + " to " +
      number_text(crowd::kMaxRateHz) + " ticks per second; search_interval: " +
      number_text(crowd::kMinSearchIntervalS) + " to " + number_text(crowd::kMaxSearchIntervalS) +
      " s. correction_half_life: seconds of the pull of each character's animated root towards its simulated "
      "position (None: the database's, from its manifest's \"crowd\" block, else " +
      number_text(crowd::kCorrectionHalfLife) + "; `mmvk crowd "
      "--correction-half-life`). speed_from_animation: play each clip faster or slower and scale its stride toward "
      "the commanded speed, the root correction held to half the animation's own speed (False: the data's own "
      "speeds; `mmvk crowd --speed-from-animation`). Every setting is checked before anything is allocated. record=True keeps the "
      "viewer's recording for write_html().";
  return doc.c_str();
}

}  // namespace

void bind_crowd(py::module_& m) {
  py::class_<PyCrowd> crowd(m, "Crowd", crowd_doc());
  add_construction(crowd);
  add_stepping(crowd);
  add_settings(crowd);
  add_state_arrays(crowd);
  add_speed_arrays(crowd);
  add_outputs(crowd);
}

}  // namespace mmvk::python
