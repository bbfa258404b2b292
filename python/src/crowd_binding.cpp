// mmvk.Crowd: the crowd host's CrowdSession (host/crowd/setup/crowd_session.hpp)
// stepped from Python, by its own steering or by another simulator's.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "output/bvh_export.hpp"
#include "bindings.hpp"
#include "setup/crowd_defaults.hpp"
#include "setup/crowd_limits.hpp"
#include "setup/crowd_session.hpp"
#include "setup/detail_agents.hpp"
#include "errors.hpp"
#include "output/gltf_export.hpp"
#include "mmvk/common/number_text.hpp"
#include "mmvk/animation/steering_input.hpp"
#include "output/pose_recording.hpp"
#include "steering/scenario.hpp"
#include "measure/summary.hpp"

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

// One agent index or a sequence (or integer array) of them.
std::vector<std::uint64_t> agent_indices(const py::object& agents) {
  if (py::isinstance<py::int_>(agents)) {
    const long long b = agents.cast<long long>();
    if (b < 0) raise("agents: " + std::to_string(b) + " is not a character of this crowd");
    return {std::uint64_t(b)};
  }
  const auto values = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(agents);
  if (!values || values.ndim() != 1) raise("agents: expected an index or a 1-D sequence of indices");
  std::vector<std::uint64_t> out;
  out.reserve(std::size_t(values.size()));
  for (const long long b : std::span(values.data(), std::size_t(values.size()))) {
    if (b < 0) raise("agents: " + std::to_string(b) + " is not a character of this crowd");
    out.push_back(std::uint64_t(b));
  }
  return out;
}

// None (no tags) or a sequence of tag names; `field` names it in errors.
std::vector<std::string> tag_names(const py::object& names, const char* field) {
  if (names.is_none()) return {};
  if (py::isinstance<py::str>(names)) raise(std::string(field) + ": expected a list of tag names, got one string");
  std::vector<std::string> out;
  for (const py::handle name : names) {
    if (!py::isinstance<py::str>(name)) raise(std::string(field) + ": expected tag names (str)");
    out.push_back(name.cast<std::string>());
  }
  return out;
}

// detail_agents: None (the first kDefaultDetailAgents), a count, a spec as
// `mmvk crowd --detail-agents` takes it ("0-9,42"), or a sequence of indices.
std::optional<crowd::DetailAgents> detail_choice(const py::object& value) {
  constexpr const char* kName = "detail_agents";
  if (value.is_none()) return std::nullopt;
  if (py::isinstance<py::str>(value)) return take(crowd::parse_detail_agents(value.cast<std::string>(), kName));
  // An integer (NumPy's too); an array also has __index__, but is a sequence.
  if (PyIndex_Check(value.ptr()) && !py::isinstance<py::iterable>(value)) {
    crowd::DetailAgents choice;
    choice.count = unsigned_argument(value, kName, std::numeric_limits<std::uint64_t>::max());
    return choice;
  }
  if (!py::isinstance<py::iterable>(value)) {
    throw py::type_error(std::string(kName) + ": expected None, a count, a spec such as '0-9,42' or a sequence of "
                         "indices, got " + std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  std::vector<std::int64_t> indices;
  for (const py::handle item : value) {
    indices.push_back(integer_argument(item, kName, std::numeric_limits<std::int64_t>::min(),
                                       std::numeric_limits<std::int64_t>::max()));
  }
  return take(crowd::detail_agents_from_list(indices, kName));
}

class PyCrowd {
 public:
  PyCrowd(std::shared_ptr<Database> database, const CrowdSessionOptions& options, std::uint32_t record_poses)
      : database_(std::move(database)) {
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
    if (record_poses > 0) {
      poses_.emplace(take(crowd::PoseRecorder::create(session_->controller().animation(), record_poses, agents_,
                                                      session_->rate_hz(), 0, "record_poses", "record_poses")));
    }
  }

  void step(const py::object& desired_velocity, const py::object& desired_facing) {
    const auto held = lock();
    if (desired_velocity.is_none()) {
      if (!desired_facing.is_none()) raise("desired_facing: given without desired_velocity");
      check_pose_room(1);
      Status status;
      {
        py::gil_scoped_release released;
        status = step_and_record();
      }
      check(status);
      return;
    }
    read_xz(desired_velocity, "desired_velocity", velocity_);
    steer(desired_facing);
  }

  // Velocities from the host's positions at the end of this tick
  // (PositionSteering, mmvk/animation/steering_input.hpp).
  void step_toward(const py::object& next_positions, const py::object& desired_facing) {
    const auto held = lock();
    read_xz(next_positions, "next_positions", next_);
    check(positions_->velocities(session_->controller().simulation(), next_, float(session_->dt()), velocity_));
    steer(desired_facing);
  }

  // Crowd.set_tags: the characters' search tags from their next search on.
  void set_tags(const py::object& agents, const py::object& require, const py::object& exclude) {
    const std::vector<std::uint64_t> which = agent_indices(agents);
    const std::vector<std::string> required = tag_names(require, "require");
    const std::vector<std::string> excluded = tag_names(exclude, "exclude");
    const auto held = lock();
    check(session_->set_tags(which, required, excluded));
  }

  void run(double seconds) {
    check(crowd::check_tick_count(seconds, session_->rate_hz(), 0, "seconds", crowd::SettingNames::Keywords));
    const auto ticks = std::uint64_t(std::llround(seconds / session_->dt()));
    const auto held = lock();
    check_pose_room(ticks);
    Status status;
    for (std::uint64_t t = 0; t < ticks && status.ok();) {
      {
        py::gil_scoped_release released;
        const auto until = std::chrono::steady_clock::now() + kSignalCheckInterval;
        do {
          status = step_and_record();
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

  // The recorded poses (record_poses), or an error naming `what`.
  HeldSession<const crowd::PoseRecording> poses(const char* what) const {
    if (!poses_) raise(std::string(what) + ": the crowd records no poses: make it with record_poses=M");
    return {lock(), poses_->recording()};
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

  // Before `ticks` more steps: an error, before any of them, when the pose
  // recording would pass its cap.
  void check_pose_room(std::uint64_t ticks) const {
    if (poses_) check(poses_->check_room(ticks));
  }

  // One tick of the crowd's own steering, and its poses recorded.
  Status step_and_record() {
    MMVK_TRY(session_->step());
    return poses_ ? poses_->record(session_->controller()) : Status{};
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
    check_pose_room(1);
    Status status;
    {
      py::gil_scoped_release released;
      status = session_->step(velocity_, yaw);
      if (status.ok() && poses_) status = poses_->record(session_->controller());
    }
    check(status);
  }

  std::shared_ptr<Database> database_;  // outlives the session
  std::unique_ptr<CrowdSession> session_;
  std::uint32_t agents_ = 0;
  std::vector<glm::vec3> velocity_, next_;  // [agents]
  std::optional<PositionSteering> positions_;  // step_toward's
  std::optional<crowd::PoseRecorder> poses_;  // the first record_poses characters' poses, every tick
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

// A copy of per-joint values of `agents` characters ([agents x joints] vec3
// or quaternions, x, y, z, w) as float32 [agents x joints x 3|4].
template <class T>
py::array per_joint_array(std::span<const T> values, std::uint32_t agents) {
  constexpr auto width = py::ssize_t(sizeof(T) / sizeof(float));
  const auto joints = py::ssize_t(values.size() / std::max<std::size_t>(agents, 1));
  py::array_t<float> out({py::ssize_t(agents), joints, width});
  std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
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
                       const py::object& correction_half_life, std::uint32_t record_poses,
                       bool speed_from_animation, const py::object& detail_agents, double wait_at_goals) {
             CrowdSessionOptions options;
             options.backend = backend;
             options.rate_hz = rate;
             options.seed = seed;
             options.search_interval_s = search_interval;
             options.foot_ik = foot_ik;
             options.speed_from_animation = speed_from_animation;
             options.wait_at_goals_s = wait_at_goals;
             options.record = record;
             options.title = title;
             if (!device.is_none()) options.device = device.cast<std::uint32_t>();
             if (!correction_half_life.is_none()) options.correction_half_life = correction_half_life.cast<float>();
             if (!scenario.is_none()) options.scenario = scenario_of(scenario);
             options.detail_agents = detail_choice(detail_agents);
             if (options.detail_agents && !record) raise("detail_agents needs record=True (the viewer's recording)");
             if (!agents.is_none()) {
               // Checked as given, before the session checks the rest (CrowdSession::create).
               const long long n = agents.cast<long long>();
               check(crowd::check_agent_count(double(n), crowd::SettingNames::Keywords));
               options.agents = std::uint64_t(n);
             }
             return std::make_unique<PyCrowd>(std::move(db), options, record_poses);
           }),
           py::arg("db"), py::arg("agents") = py::none(), py::arg("backend") = kDefaults.backend,
           py::arg("rate") = kDefaults.rate_hz, py::arg("seed") = kDefaults.seed, py::arg("device") = py::none(),
           py::arg("scenario") = py::none(), py::arg("search_interval") = kDefaults.search_interval_s,
           py::arg("foot_ik") = kDefaults.foot_ik, py::arg("record") = false,
           py::arg("title") = "", py::arg("correction_half_life") = py::none(), py::arg("record_poses") = 0,
           py::arg("speed_from_animation") = kDefaults.speed_from_animation, py::arg("detail_agents") = py::none(),
           py::arg("wait_at_goals") = kDefaults.wait_at_goals_s);
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
           "(mmvk/animation/steering_input.hpp: PositionSteering). desired_facing as for step().")
      .def("set_tags", &PyCrowd::set_tags, py::arg("agents"), py::arg("require") = py::none(),
           py::arg("exclude") = py::none(),
           "set_tags(agents, require=None, exclude=None) -> None\n\n"
           "The tags the characters `agents` (an index or a sequence of them) search with from their next search "
           "on (within search_interval): candidates must carry every `require` tag and none of the `exclude` "
           "tags; both replace what the characters had (a scenario's gait tags included). The measured gait "
           "tags ('gait:stand', 'gait:walk', 'gait:jog', 'gait:run', 'gait:start', 'gait:stop'; Database.tags) "
           "change a character's gait at any tick. Errors, before anything changes: an agent out of range, an "
           "unknown tag (listing the known ones), a tag both required and excluded.")
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
          "gaits",
          [](const PyCrowd& c) {
            const auto states = c.session()->controller().gait_states();
            py::array_t<std::uint8_t> out({py::ssize_t(c.agents()), py::ssize_t(2)});
            std::uint8_t* o = out.mutable_data();
            for (std::size_t b = 0; b < states.size(); ++b) {
              o[2 * b] = std::uint8_t(states[b].band), o[2 * b + 1] = std::uint8_t(states[b].phase);
            }
            return out;
          },
          "Each character's commanded gait after the last step, uint8 [agents x 2]: the band (0 stand, 1 walk, "
          "2 jog, 3 run) and the phase (0 stand, 1 start, 2 move, 3 stop), as the controller chose them from the "
          "desired velocity (docs/animation.md, \"Gait from the command\"); zeros on data without measured gait "
          "tags.")
      .def_property_readonly(
          "resting",
          [](const PyCrowd& c) { return copy_array(c.session()->controller().resting(), {py::ssize_t(c.agents())}); },
          "1 while a character told to stand holds a frame with both feet down (the data's rest frame where "
          "it has no idle, or a standing frame of a clip that goes on), uint8 [agents].")
      .def_property_readonly(
          "foot_locked",
          [](const PyCrowd& c) {
            return copy_array(c.session()->controller().foot_locked(), {py::ssize_t(c.agents()), 2});
          },
          "1 while a foot (left, right) is held where it was planted, uint8 [agents x 2].")
      .def_property_readonly(
          "foot_corrections",
          [](const PyCrowd& c) {
            return vec3_array(c.session()->controller().foot_corrections(), {py::ssize_t(c.agents()), 2, 3});
          },
          "How far each displayed foot (left, right) is held from its animated pose after the last step: the "
          "foot lock's horizontal correction, world metres, float32 [agents x 2 x 3] (y = 0; zeros with foot IK "
          "off).")
      .def_property_readonly(
          "joint_positions",
          [](const PyCrowd& c) { return per_joint_array(c.session()->world_positions(), c.agents()); },
          "The displayed global joint positions after the last step (foot IK included), float32 [agents x joints "
          "x 3], metres.");
}

// The displayed pose after the last step (after foot IK), as a renderer
// skinning a mesh takes it: the skeleton, the roots and the local rotations.
void add_pose_arrays(py::class_<PyCrowd>& crowd) {
  crowd
      .def_property_readonly(
          "skeleton",
          [](const PyCrowd& c) {
            const auto session = c.session();
            const AnimationData& animation = session->controller().animation();
            const Skeleton& skeleton = animation.skeleton;
            py::dict out;
            out["names"] = skeleton.names;
            out["parents"] = copy_array(std::span<const int>(skeleton.parents), {py::ssize_t(skeleton.size())});
            out["rest_offsets"] = vec3_array(skeleton.rest_offsets, {py::ssize_t(skeleton.size()), 3});
            out["translated_joints"] = animation.translated_joints;
            return out;
          },
          "The database's skeleton: names, parents (int32, -1 for a root), rest_offsets (float32 [joints x 3], "
          "metres, in the parent's frame) and translated_joints (the joints whose translation varies: the hips).")
      .def_property_readonly(
          "local_rotations",
          [](const PyCrowd& c) { return per_joint_array(c.session()->controller().local_rotations(), c.agents()); },
          "The displayed pose's local joint rotations (after foot IK), float32 [agents x joints x 4], unit "
          "quaternions (x, y, z, w) in the parent's frame; a root's (and so the hips') in character space, placed "
          "by root_positions and root_rotations.")
      .def_property_readonly(
          "local_translations",
          [](const PyCrowd& c) {
            return per_joint_array(c.session()->controller().local_translations(), c.agents());
          },
          "The displayed pose's local joint translations, float32 [agents x joints x 3], metres: the rest offsets, "
          "and the translated joints' own (the hips, lowered by foot IK where it drops them).")
      .def_property_readonly(
          "root_rotations",
          [](const PyCrowd& c) {
            const auto yaws = c.session()->controller().root_yaws();
            std::vector<glm::quat> rotations(yaws.size());
            std::transform(yaws.begin(), yaws.end(), rotations.begin(),
                           [](float yaw) { return glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f)); });
            // [agents x 1 x 4] as [agents x 4].
            return per_joint_array(std::span<const glm::quat>(rotations), c.agents()).attr("reshape")(c.agents(), 4);
          },
          "Each character's root rotation R_y(root_yaws), float32 [agents x 4] (x, y, z, w). A joint's world "
          "transform is T(root_positions) * R(root_rotations) * the chain of T(local_translations) * "
          "R(local_rotations) from its root.");
}

// `write` (a Status of the recording) with the GIL released; its error
// raised as OSError once the GIL is back. Errors: no poses recorded, naming `what`.
template <class Write>
void write_poses(const PyCrowd& c, const char* what, const Write& write) {
  const auto poses = c.poses(what);
  Status written;
  {
    py::gil_scoped_release released;
    written = write(*poses.operator->());
  }
  check(written, ErrorKind::OS);
}

// The recorded poses (record_poses=M) written as BVH and glTF.
void add_exports(py::class_<PyCrowd>& crowd) {
  crowd
      .def(
          "write_bvh",
          [](const PyCrowd& c, const py::object& folder) {
            const std::filesystem::path dir = to_path(folder, "folder");
            write_poses(c, "write_bvh", [&dir](const crowd::PoseRecording& poses) -> Status {
              MMVK_TRY(crowd::check_bvh_folder(dir, poses.agents, "folder"));
              return crowd::write_bvh_files(poses, dir);
            });
          },
          py::arg("folder"),
          "Writes one BVH per recorded character (record_poses=M), folder/agent_0000.bvh ...: the displayed pose "
          "of every step so far at the tick rate on the database's skeleton (`mmvk crowd --bvh`). The folder is "
          "made when missing.")
      .def(
          "write_gltf",
          [](const PyCrowd& c, const py::object& path) {
            const std::filesystem::path p = to_path(path, "path");
            write_poses(c, "write_gltf", [&p](const crowd::PoseRecording& poses) -> Status {
              MMVK_TRY(crowd::check_gltf_path(p, "path"));
              return crowd::write_gltf(poses, p);
            });
          },
          py::arg("path"),
          "Writes the recorded characters (record_poses=M) into one glTF 2.0 binary (.glb): each a skin over its "
          "joint nodes, animated at the tick rate (`mmvk crowd --gltf`).");
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
                    "The scale of each character's root motion in the last step (0: a standing frame played in place "
                    "while told to stand), float32 [agents].");
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
      "search_interval=0.1, foot_ik=True, record=False, title='', correction_half_life=None, record_poses=0, "
      "speed_from_animation=True, detail_agents=None, wait_at_goals=0.0). agents: the number of "
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
      "speeds; `mmvk crowd --speed-from-animation`). wait_at_goals: seconds the drawn characters stand at each goal "
      "before the next (`mmvk crowd --wait-at-goals`; a scenario sets its own, \"wait_s\"). Every setting is "
      "checked before anything is allocated. "
      "record=True keeps the viewer's recording for write_html(); detail_agents chooses the characters it keeps "
      "in detail, their whole pose every tick and every search explained (None: the first " +
      std::to_string(crowd::kDefaultDetailAgents) + ", or the crowd when smaller; a count N: the first N; a spec "
      "such as '0-9,42,100-104' as `mmvk crowd --detail-agents` takes it; or a sequence of indices). "
      "record_poses=M keeps the displayed poses of the first M characters every tick for write_bvh() and "
      "write_gltf().";
  return doc.c_str();
}

}  // namespace

void bind_crowd(py::module_& m) {
  py::class_<PyCrowd> crowd(m, "Crowd", crowd_doc());
  add_construction(crowd);
  add_stepping(crowd);
  add_settings(crowd);
  add_state_arrays(crowd);
  add_pose_arrays(crowd);
  add_exports(crowd);
  add_speed_arrays(crowd);
  add_outputs(crowd);
}

}  // namespace mmvk::python
