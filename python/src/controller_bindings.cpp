// mm.Controller: one character driven from Python, its pose out as numpy arrays.

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "mm/controller/local_origin.hpp"
#include "mm/runtime/interpolation.hpp"

namespace mm::python {
namespace {

py::tuple world_point(const glm::dvec3& origin, const glm::vec3& local) {
  const glm::dvec3 p = to_world(origin, local);
  return py::make_tuple(p.x, p.y, p.z);
}

class PyController {
 public:
  PyController(std::shared_ptr<DatabaseHandle> database, const py::kwargs& settings)
      : database_(std::move(database)) {
    const ControllerSettings chosen = settings_from_kwargs(ControllerSettings{}, settings);
    Result<Controller> made = Controller::create(database_->controller_database(), chosen);
    if (!made) throw LibraryError(made.message());
    controller_.emplace(std::move(made).value());
  }

  void update(float dt, std::array<float, 2> left_stick, std::array<float, 2> right_stick, bool run,
              bool strafe, float camera_yaw, std::optional<float> facing_yaw,
              const std::string& tag) {
    ControllerInput input;
    input.left_stick = glm::vec2(left_stick[0], left_stick[1]);
    input.right_stick = glm::vec2(right_stick[0], right_stick[1]);
    input.run = run;
    input.strafe = strafe;
    input.camera_yaw = camera_yaw;
    if (facing_yaw) input.facing_yaw = *facing_yaw;
    input.tag = tag;
    input.tag_bits = controller_->controller_database().tag_bits(tag);
    controller_->update(dt, input);
  }

  void set_settings(const py::kwargs& settings) {
    const ControllerSettings changed = settings_from_kwargs(controller_->settings(), settings);
    if (Status s = controller_->set_settings(changed); !s) throw py::value_error(s.message());
  }

  void teleport(float x, float z, float yaw) {
    if (!std::isfinite(x) || !std::isfinite(z) || !std::isfinite(yaw)) {
      throw py::value_error("teleport: x, z and yaw must be finite");
    }
    controller_->teleport_world(glm::dvec3(x, 0.0, z), yaw);
  }

  // Every joint's global position, world metres (float: exact near the world origin), and
  // rotation.
  py::array_t<float> positions() const {
    return translation_array(controller_->global_transforms());
  }
  py::array_t<float> rotations() const { return rotation_array(controller_->global_transforms()); }

  // Row-major 4x4 matrices (numpy's order: m[joint] @ [x, y, z, 1] transforms a bind-pose
  // point); GLM stores them column by column.
  py::array_t<float> skinning_matrices() const {
    const auto matrices = controller_->skinning_matrices();
    py::array_t<float> out(
        {static_cast<py::ssize_t>(matrices.size()), py::ssize_t{4}, py::ssize_t{4}});
    auto o = out.mutable_unchecked<3>();
    for (size_t j = 0; j < matrices.size(); ++j) {
      for (int row = 0; row < 4; ++row) {
        for (int col = 0; col < 4; ++col) {
          o(static_cast<py::ssize_t>(j), row, col) = matrices[j][col][row];
        }
      }
    }
    return out;
  }

  py::dict state() const {
    const ControllerDebug& d = controller_->debug();
    const glm::dvec3 root = controller_->world_root_position();
    py::dict s;
    s["origin"] = py::make_tuple(d.origin.x, d.origin.y, d.origin.z);
    s["root_position"] = py::make_tuple(root.x, root.y, root.z);
    s["root_yaw"] = quat_yaw(controller_->root_transform().rotation);
    s["simulation_position"] = world_point(d.origin, d.simulation_position);
    s["simulation_yaw"] = quat_yaw(d.simulation_rotation);
    s["desired_velocity"] =
        py::make_tuple(d.desired_velocity.x, d.desired_velocity.y, d.desired_velocity.z);
    s["desired_yaw"] = quat_yaw(d.desired_rotation);
    s["clip"] = d.clip;
    s["frame"] = d.frame;
    s["transitioned"] = d.transitioned;
    s["transitions"] = d.transitions;
    s["searches"] = d.searches;
    s["contacts"] = py::make_tuple(d.contact[0], d.contact[1]);
    s["locked"] = py::make_tuple(d.locked[0], d.locked[1]);
    return s;
  }

  const Controller& controller() const { return *controller_; }

 private:
  std::shared_ptr<DatabaseHandle> database_;
  std::optional<Controller> controller_;
};

}  // namespace

void bind_controller(py::module_& m) {
  py::class_<PyController>(m, "Controller",
                           "One character: update(dt, ...) every frame, the pose out as numpy "
                           "arrays. Settings are keyword arguments named as ControllerSettings' "
                           "fields (mm eval --set NAME=VALUE), e.g. ik_enabled=False.")
      .def(py::init<std::shared_ptr<DatabaseHandle>, const py::kwargs&>(), py::arg("database"))
      .def("update", &PyController::update, py::arg("dt"),
           py::arg("left_stick") = std::array<float, 2>{0.0f, 0.0f},
           py::arg("right_stick") = std::array<float, 2>{0.0f, 0.0f}, py::arg("run") = false,
           py::arg("strafe") = false, py::arg("camera_yaw") = 0.0f,
           py::arg("facing_yaw") = py::none(), py::arg("tag") = std::string(),
           "Advances dt seconds. Sticks are (x right, y forward) relative to the camera, whose "
           "yaw is radians about +Y; facing_yaw (radians, world) makes the character turn to "
           "and keep that facing; tag plays clips carrying it. Out-of-range or non-finite input "
           "is sanitized by the controller, never kept.")
      .def("set_settings", &PyController::set_settings,
           "Changes settings by name between updates (ValueError on unknown or invalid ones, "
           "changing nothing).")
      .def("teleport", &PyController::teleport, py::arg("x"), py::arg("z"), py::arg("yaw") = 0.0f,
           "Places the character at world (x, 0, z) facing yaw (radians).")
      .def_property_readonly("positions", &PyController::positions,
                             "(joints, 3) float32: every joint's global position, world metres")
      .def_property_readonly("rotations", &PyController::rotations,
                             "(joints, 4) float32: every joint's global rotation, quaternions "
                             "(x, y, z, w)")
      .def_property_readonly("skinning_matrices", &PyController::skinning_matrices,
                             "(joints, 4, 4) float32, row-major: global * inverse bind")
      .def_property_readonly("state", &PyController::state,
                             "the simulation, desired motion and playback after the last "
                             "update (positions world metres, yaws radians)")
      .def_property_readonly("joint_names", [](const PyController& c) {
        return c.controller().controller_database().database().skeleton().names();
      });
}

}  // namespace mm::python
