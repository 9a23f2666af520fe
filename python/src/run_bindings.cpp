// mm.build_database, mm.run_script and mm.evaluate: the `mm build` and `mm eval` runs from
// Python, the same code underneath, so that their results equal the command line's.

#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "mm/controller/local_origin.hpp"
#include "mm/controller/script.hpp"
#include "mm/offline/database_writer.hpp"
#include "mm/offline/joint_map.hpp"
#include "mm/programs/evaluation.hpp"
#include "mm/programs/evaluation_json.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/level.hpp"

namespace mm::python {
namespace {

// ---- mm.build_database

BuildOptions build_options(float rate, bool mirror, float idle, const py::object& tags,
                           const py::object& joint_map, float scale, int threads, bool skip_bad) {
  BuildOptions options;
  options.rate = rate;
  options.mirror = mirror;
  options.idle_seconds = idle;
  options.bvh.scale = scale;
  options.threads = threads;
  options.skip_bad = skip_bad;
  if (!tags.is_none()) options.tags_file = tags.cast<std::filesystem::path>();
  if (!joint_map.is_none()) {
    const auto path = joint_map.cast<std::filesystem::path>();
    Result<std::vector<JointRoleAssignment>> map = load_joint_map(path);
    if (!map) raise_for_file(map.message(), path);
    options.role_map = std::move(map).value();
  }
  return options;
}

// Calls the Python progress callback from the builder's worker threads (never two at a time),
// holding the interpreter's lock. An exception it raises is kept and raised once the build
// returns; later calls are skipped.
class ProgressRelay {
 public:
  explicit ProgressRelay(py::object callback) : callback_(std::move(callback)) {}
  ~ProgressRelay() {
    py::gil_scoped_acquire gil;
    callback_ = py::object();
  }

  void operator()(size_t done, size_t total) {
    if (error_) return;
    py::gil_scoped_acquire gil;
    try {
      callback_(done, total);
    } catch (py::error_already_set&) {
      error_ = std::current_exception();
    }
  }

  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  py::object callback_;
  std::exception_ptr error_;
};

std::shared_ptr<DatabaseHandle> build(const std::vector<std::filesystem::path>& inputs,
                                      const std::filesystem::path& output, float rate, bool mirror,
                                      float idle, const py::object& tags,
                                      const py::object& joint_map, float scale, int threads,
                                      bool skip_bad, const py::object& progress) {
  BuildOptions options =
      build_options(rate, mirror, idle, tags, joint_map, scale, threads, skip_bad);
  std::shared_ptr<ProgressRelay> relay;
  if (!progress.is_none()) {
    relay = std::make_shared<ProgressRelay>(progress);
    options.progress = [relay](size_t done, size_t total) { (*relay)(done, total); };
  }
  BuildReport report;
  std::optional<Result<Database>> built;
  Status saved = Status::success();
  {
    py::gil_scoped_release release;
    built.emplace(build_database(inputs, options, &report));
    if (*built) saved = save_database(**built, output);
    options.progress = nullptr;
  }
  if (relay) relay->rethrow();
  if (!*built) {
    // A missing input is the likeliest failure: FileNotFoundError, with the builder's message.
    for (const std::filesystem::path& input : inputs) raise_if_missing(built->message(), input);
    throw LibraryError(built->message());
  }
  if (!saved) throw LibraryError(saved.message());
  for (const std::string& w : report.warnings) {
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
  }
  auto handle = std::make_shared<DatabaseHandle>();
  handle->database = std::make_shared<const Database>(std::move(*built).value());
  handle->path = output;
  handle->report = std::move(report);
  return handle;
}

// ---- mm.run_script and mm.evaluate

// The options of a run, as `mm eval` takes them. Raises ValueError on a bad one.
EvaluationOptions run_options(float dt, bool ik, float seconds, std::pair<double, double> start,
                              const py::kwargs& settings) {
  if (!(dt >= kMinRunDt && dt <= kMaxRunDt)) {
    throw py::value_error("dt must be in [" + std::to_string(kMinRunDt) + ", " +
                          std::to_string(kMaxRunDt) + "] seconds, not " + std::to_string(dt));
  }
  EvaluationOptions options;
  options.dt = dt;
  options.seconds = seconds;
  options.start = glm::dvec2(start.first, start.second);
  ControllerSettings base;
  base.ik_enabled = ik;
  options.settings = settings_from_kwargs(base, settings);
  return options;
}

InputScript load_script(const std::filesystem::path& path) {
  Result<InputScript> script = load_input_script(path);
  if (!script) raise_for_file(script.message(), path);
  return std::move(script).value();
}

// The level at `path` as a Bullet world (mm eval --world); a bad file raises (FileNotFoundError
// when it does not exist, else mm.LibraryError with the loader's message).
std::optional<BulletWorld> open_world(const std::optional<std::filesystem::path>& path) {
  if (!path) return std::nullopt;
  Result<Level> level = load_level(*path);
  if (!level) raise_for_file(level.message(), *path);
  Result<BulletWorld> made = BulletWorld::create(*level);
  if (!made) throw LibraryError(made.message());
  return std::move(made).value();
}

// Runs the script; every failure raises.
EvaluationResult run(DatabaseHandle& database, const InputScript& script,
                     const EvaluationOptions& options) {
  const std::shared_ptr<const ControllerDatabase> shared = database.controller_database();
  Result<EvaluationResult> result = [&] {
    py::gil_scoped_release release;
    return evaluate_script(shared, script, options);
  }();
  if (!result) throw LibraryError(result.message());
  return std::move(result).value();
}

// A numpy array that takes over a vector's memory (no copy).
template <typename T>
py::array_t<T> take(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(std::move(shape), owned->data(), free);
}

// The run frame by frame, as the CSV dump has it (world positions, yaws in degrees), in
// columns that become the arrays.
struct RunColumns {
  size_t joints = 0;
  std::vector<double> t, positions, root, root_yaw, simulation, simulation_yaw;
  std::vector<double> desired_velocity, desired_yaw;
  std::vector<uint8_t> transition, contacts, stuck;
  std::vector<int32_t> clip, frame;
  std::vector<double> toe_ground, hips_ground, wall_depth;

  static void push(std::vector<double>& out, const glm::dvec3& p) {
    out.insert(out.end(), {p.x, p.y, p.z});
  }

  void add(const EvaluationFrame& r) {
    t.push_back(r.t);
    for (const glm::vec3& joint : r.joints) push(positions, to_world(r.origin, joint));
    push(root, to_world(r.origin, r.root_position));
    root_yaw.push_back(glm::degrees(r.root_yaw));
    push(simulation, to_world(r.origin, r.sim_position));
    simulation_yaw.push_back(glm::degrees(r.sim_yaw));
    push(desired_velocity, glm::dvec3(r.desired_velocity));
    desired_yaw.push_back(glm::degrees(r.desired_yaw));
    transition.push_back(r.transition ? 1 : 0);
    contacts.insert(contacts.end(), {uint8_t{r.contact[0]}, uint8_t{r.contact[1]}});
    clip.push_back(r.clip);
    frame.push_back(r.frame);
    toe_ground.insert(toe_ground.end(), {r.toe_ground[0], r.toe_ground[1]});
    hips_ground.push_back(r.hips_ground);
    wall_depth.push_back(r.wall_depth);
    stuck.push_back(r.stuck ? 1 : 0);
  }

  py::dict arrays() && {
    const auto n = static_cast<py::ssize_t>(t.size());
    const auto j = static_cast<py::ssize_t>(joints);
    py::dict out;
    out["t"] = take(std::move(t), {n});
    out["positions"] = take(std::move(positions), {n, j, 3});
    out["root"] = take(std::move(root), {n, 3});
    out["root_yaw_deg"] = take(std::move(root_yaw), {n});
    out["simulation"] = take(std::move(simulation), {n, 3});
    out["simulation_yaw_deg"] = take(std::move(simulation_yaw), {n});
    out["desired_velocity"] = take(std::move(desired_velocity), {n, 3});
    out["desired_yaw_deg"] = take(std::move(desired_yaw), {n});
    out["transition"] = take(std::move(transition), {n}).attr("astype")("bool");
    out["contacts"] = take(std::move(contacts), {n, 2}).attr("astype")("bool");
    out["clip"] = take(std::move(clip), {n});
    out["frame"] = take(std::move(frame), {n});
    out["toe_ground"] = take(std::move(toe_ground), {n, 2});
    out["hips_ground"] = take(std::move(hips_ground), {n});
    out["wall_depth"] = take(std::move(wall_depth), {n});
    out["stuck"] = take(std::move(stuck), {n}).attr("astype")("bool");
    return out;
  }
};

py::dict run_script(const std::shared_ptr<DatabaseHandle>& database,
                    const std::filesystem::path& script_path, float dt, bool ik, float seconds,
                    std::pair<double, double> start,
                    const std::optional<std::filesystem::path>& world_path,
                    const py::kwargs& settings) {
  EvaluationOptions options = run_options(dt, ik, seconds, start, settings);
  const InputScript script = load_script(script_path);
  const std::optional<BulletWorld> world = open_world(world_path);
  if (world) options.world = &*world;
  RunColumns columns;
  columns.joints = static_cast<size_t>(database->database->joint_count());
  options.on_frame = [&columns](const EvaluationFrame& frame) { columns.add(frame); };
  run(*database, script, options);
  return std::move(columns).arrays();
}

py::object evaluate(const std::shared_ptr<DatabaseHandle>& database,
                    const std::filesystem::path& script_path, float dt, bool ik, float seconds,
                    std::pair<double, double> start,
                    const std::optional<std::filesystem::path>& world_path,
                    const py::kwargs& settings) {
  EvaluationOptions options = run_options(dt, ik, seconds, start, settings);
  const InputScript script = load_script(script_path);
  const std::optional<BulletWorld> world = open_world(world_path);
  if (world) options.world = &*world;
  const EvaluationResult result = run(*database, script, options);
  nlohmann::json json = evaluation_run_json(result.metrics, script_path.string(), options);
  if (world_path) json["world"] = world_path->string();  // as mm eval --json names it
  return py::module_::import("json").attr("loads")(json.dump());
}

}  // namespace

void bind_runs(py::module_& m) {
  m.def("build_database", &build, py::arg("inputs"), py::arg("output"), py::kw_only(),
        py::arg("rate") = 30.0f, py::arg("mirror") = false, py::arg("idle") = 3.0f,
        py::arg("tags") = py::none(), py::arg("map") = py::none(), py::arg("scale") = 0.0f,
        py::arg("threads") = 0, py::arg("skip_bad") = false, py::arg("progress") = py::none(),
        "Builds a database from BVH / glTF files and folders and writes it to `output`, as "
        "`mm build` does (rate Hz, --mirror, --idle SECONDS, --tags FILE, --map FILE, --scale S "
        "(0: units per file), --threads N, --skip-bad). progress(done, total) is called as it "
        "goes. The builder's warnings become Python warnings; the report is the database's "
        "build_report.");
  m.def("run_script", &run_script, py::arg("database"), py::arg("script"),
        py::arg("dt") = kDefaultRunDt, py::arg("ik") = true, py::arg("seconds") = 0.0f,
        py::arg("start") = std::pair<double, double>{0.0, 0.0}, py::arg("world") = py::none(),
        "Runs one controller on a script (mm eval's run; world: a level file, .gltf or .glb, "
        "as mm eval --world; settings as keyword arguments) and "
        "returns every frame as numpy arrays: t (frames,), positions (frames, joints, 3) world "
        "metres, root and simulation (frames, 3) with root_yaw_deg and simulation_yaw_deg, "
        "desired_velocity (frames, 3) and desired_yaw_deg, transition (frames,) and contacts "
        "(frames, 2) bool, clip and frame (frames,) int32, toe_ground (frames, 2), hips_ground and "
        "wall_depth (frames,) metres and stuck (frames,) bool: the columns of mm eval --dump.");
  m.def("evaluate", &evaluate, py::arg("database"), py::arg("script"),
        py::arg("dt") = kDefaultRunDt, py::arg("ik") = true, py::arg("seconds") = 0.0f,
        py::arg("start") = std::pair<double, double>{0.0, 0.0}, py::arg("world") = py::none(),
        "Runs one controller on a script (world: a level file, as mm eval --world) and returns "
        "its metrics: the keys and values of mm eval --json.");
}

}  // namespace mm::python
