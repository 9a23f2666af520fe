// mm.Database and mm.load_database: a database's arrays as read-only numpy views of its own
// memory, and its names.

#include <cstddef>
#include <cstring>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "mm/database/database_file.hpp"
#include "mm/runtime/pose.hpp"

namespace mm::python {
namespace {

// The views below read GLM's vectors and quaternions as packed floats, quaternions as x, y, z, w.
static_assert(sizeof(glm::vec3) == 3 * sizeof(float) && sizeof(glm::quat) == 4 * sizeof(float));
#ifdef GLM_FORCE_QUAT_DATA_WXYZ
#error "the numpy views of quaternions are (x, y, z, w): GLM's storage must be x, y, z, w"
#endif

using Handle = std::shared_ptr<DatabaseHandle>;

// A read-only array over `data` that keeps `owner` (the Python database object) alive: no copy.
template <typename T>
py::array read_only_view(const T* data, std::vector<py::ssize_t> shape, const py::object& owner) {
  py::array view(py::dtype::of<T>(), std::move(shape), data, owner);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

// A read-only array of the values of a database's pose (vec3 or quat, read as GLM stores them:
// x, y, z[, w]), copied out of the lanes the database keeps them in.
template <typename T>
py::array read_only_copy(const JointValues<T>& values, std::vector<py::ssize_t> shape) {
  constexpr size_t kComponents = sizeof(T) / sizeof(float);
  py::array_t<float> copy(std::move(shape));
  float* out = copy.mutable_data();
  for (size_t k = 0; k < values.size(); ++k) {
    const T v = values[k];
    std::memcpy(out + kComponents * k, &v, sizeof v);
  }
  copy.attr("setflags")(py::arg("write") = false);
  return copy;
}

const Database& db_of(const Handle& handle) {
  return *handle->database;
}

void check_frame(const Database& db, int frame) {
  if (frame < 0 || frame >= db.frame_count()) {
    throw py::index_error("frame " + std::to_string(frame) + " is outside the database's " +
                          std::to_string(db.frame_count()) + " frames");
  }
}

// The global transforms of every joint at one database frame.
std::vector<Transform> global_pose(const Database& db, int frame) {
  check_frame(db, frame);
  const size_t joints = static_cast<size_t>(db.joint_count());
  std::vector<Transform> local(joints), global(joints);
  for (size_t j = 0; j < joints; ++j) {
    local[j].translation = db.local_position(frame, static_cast<int>(j));
    local[j].rotation = db.local_rotation(frame, static_cast<int>(j));
  }
  forward_kinematics(db.skeleton().parents(), local, global);
  return global;
}

py::array_t<float> positions_at(const Handle& handle, int frame) {
  return translation_array(global_pose(db_of(handle), frame));
}

py::array_t<float> rotations_at(const Handle& handle, int frame) {
  return rotation_array(global_pose(db_of(handle), frame));
}

std::vector<std::string> tag_names_of(const Database& db, uint64_t tags) {
  std::vector<std::string> names;
  for (size_t i = 0; i < db.tag_names().size(); ++i) {
    if (tags & (uint64_t{1} << i)) names.push_back(db.tag_names()[i]);
  }
  return names;
}

py::list clips_of(const Database& db) {
  py::list clips;
  for (const ClipRange& c : db.clips()) {
    py::dict clip;
    clip["name"] = c.name;
    clip["start"] = c.start;
    clip["end"] = c.end;
    clip["tags"] = tag_names_of(db, c.tags);
    clip["mirrored"] = c.mirrored;
    clips.append(std::move(clip));
  }
  return clips;
}

py::object report_of(const DatabaseHandle& handle) {
  if (!handle.report) return py::none();
  const BuildReport& r = *handle.report;
  py::list refused;
  for (const RefusedInput& input : r.refused) {
    refused.append(py::make_tuple(input.path.string(), input.message));
  }
  py::dict report;
  report["inputs"] = r.inputs;
  report["clips"] = r.clips;
  report["frames"] = r.frames;
  report["searchable_frames"] = r.searchable_frames;
  report["duration_s"] = r.duration_s;
  report["threads"] = r.threads;
  report["total_seconds"] = r.total_seconds;
  report["warnings"] = r.warnings;
  report["retargeted"] = r.retargeted;
  report["refused"] = refused;
  return report;
}

py::list channels_of(const Database& db) {
  static constexpr const char* kKinds[] = {"bone_position", "bone_velocity", "trajectory_position",
                                           "trajectory_direction", "bone_direction"};
  const FeatureSchema& schema = db.schema();
  py::list channels;
  for (size_t i = 0; i < schema.channels.size(); ++i) {
    const FeatureChannel& c = schema.channels[i];
    const int first = schema.offset(static_cast<int>(i));
    py::dict channel;
    channel["name"] = c.name;
    channel["kind"] = kKinds[static_cast<size_t>(c.kind)];
    channel["bone"] = c.bone;
    channel["times"] = c.times;
    channel["weight"] = c.weight;
    channel["columns"] = py::make_tuple(first, first + c.dims());
    channels.append(std::move(channel));
  }
  return channels;
}

// A copy with the named channels' weights changed (with_channel_weight, one channel at a time).
Handle with_weights(const Handle& handle, const py::kwargs& weights) {
  const FeatureSchema& schema = db_of(handle).schema();
  std::shared_ptr<const Database> current = handle->database;
  for (const auto& [key, value] : weights) {
    const std::string name = py::str(key);
    int channel = -1;
    for (size_t i = 0; i < schema.channels.size(); ++i) {
      if (schema.channels[i].name == name) channel = static_cast<int>(i);
    }
    if (channel < 0) {
      std::string known;
      for (const FeatureChannel& c : schema.channels) known += (known.empty() ? "" : ", ") + c.name;
      throw py::value_error("feature weight: no channel named '" + name + "' (" + known + ")");
    }
    Result<Database> changed = with_channel_weight(*current, channel, value.cast<float>());
    if (!changed) throw py::value_error(changed.message());
    current = std::make_shared<const Database>(std::move(changed).value());
  }
  auto copy = std::make_shared<DatabaseHandle>();
  copy->database = std::move(current);
  copy->path = handle->path;
  return copy;
}

Handle load(const std::filesystem::path& path) {
  Result<Database> loaded = [&] {
    py::gil_scoped_release release;
    return load_database(path);
  }();
  if (!loaded) raise_for_file(loaded.message(), path);
  auto handle = std::make_shared<DatabaseHandle>();
  handle->database = std::make_shared<const Database>(std::move(loaded).value());
  handle->path = path;
  return handle;
}

std::string repr(const Handle& handle) {
  const Database& db = db_of(handle);
  return "<mm.Database " + handle->path.string() + ": " + std::to_string(db.frame_count()) +
         " frames, " + std::to_string(db.clips().size()) + " clips, " +
         std::to_string(db.joint_count()) + " joints, " + std::to_string(db.feature_dims()) +
         " features>";
}

}  // namespace

std::shared_ptr<const ControllerDatabase> DatabaseHandle::controller_database() {
  if (!controller_database_) {
    Result<std::shared_ptr<const ControllerDatabase>> made = ControllerDatabase::create(database);
    if (!made) throw LibraryError(made.message());
    controller_database_ = std::move(made).value();
  }
  return controller_database_;
}

void bind_database(py::module_& m) {
  py::class_<DatabaseHandle, Handle> database(
      m, "Database",
      "A motion database (immutable). Its per-frame arrays are read-only numpy views of the "
      "database's own memory: they keep it alive while they exist.");
  database.def_property_readonly("path", [](const Handle& h) { return h->path; })
      .def_property_readonly("frame_count", [](const Handle& h) { return db_of(h).frame_count(); })
      .def_property_readonly("joint_count", [](const Handle& h) { return db_of(h).joint_count(); })
      .def_property_readonly("feature_dims",
                             [](const Handle& h) { return db_of(h).feature_dims(); })
      .def_property_readonly(
          "frame_time", [](const Handle& h) { return db_of(h).frame_time(); },
          "seconds between frames")
      .def_property_readonly("joint_names",
                             [](const Handle& h) { return db_of(h).skeleton().names(); })
      .def_property_readonly(
          "parents", [](const Handle& h) { return db_of(h).skeleton().parents(); },
          "each joint's parent index, -1 for the root (joint 0, the "
          "simulation root)")
      .def_property_readonly("clip_names",
                             [](const Handle& h) {
                               std::vector<std::string> names;
                               for (const ClipRange& c : db_of(h).clips()) names.push_back(c.name);
                               return names;
                             })
      .def_property_readonly(
          "clips", [](const Handle& h) { return clips_of(db_of(h)); },
          "one dict per clip: name, start, end (one past the last frame), "
          "tags (names), mirrored")
      .def_property_readonly("tag_names",
                             [](const Handle& h) {
                               const auto names = db_of(h).tag_names();
                               return std::vector<std::string>(names.begin(), names.end());
                             })
      .def_property_readonly(
          "feature_names", [](const Handle& h) { return db_of(h).schema().column_names(); },
          "one name per column of features")
      .def_property_readonly(
          "features",
          [](const py::object& self) {
            const Database& db = db_of(self.cast<Handle>());
            return read_only_view(db.features().data(), {db.frame_count(), db.feature_dims()},
                                  self);
          },
          "(frames, dimensions) float32, normalized: (raw - feature_offset) / feature_scale; a "
          "read-only view, no copy")
      .def_property_readonly("feature_offset",
                             [](const py::object& self) {
                               const Database& db = db_of(self.cast<Handle>());
                               return read_only_view(db.feature_offset().data(),
                                                     {db.feature_dims()}, self);
                             })
      .def_property_readonly("feature_scale",
                             [](const py::object& self) {
                               const Database& db = db_of(self.cast<Handle>());
                               return read_only_view(db.feature_scale().data(), {db.feature_dims()},
                                                     self);
                             })
      .def_property_readonly(
          "contacts",
          [](const py::object& self) {
            const Database& db = db_of(self.cast<Handle>());
            return read_only_view(db.contacts().data(), {db.frame_count(), 2}, self);
          },
          "(frames, 2) uint8: left, right foot in contact")
      .def_property_readonly("searchable",
                             [](const py::object& self) {
                               const Database& db = db_of(self.cast<Handle>());
                               return read_only_view(db.searchable().data(), {db.frame_count()},
                                                     self);
                             })
      .def_property_readonly(
          "frame_clip",
          [](const py::object& self) {
            const Database& db = db_of(self.cast<Handle>());
            return read_only_view(db.frame_clip().data(), {db.frame_count()}, self);
          },
          "(frames,) int32: the clip of each frame")
      .def_property_readonly(
          "local_positions",
          [](const py::object& self) {
            const Database& db = db_of(self.cast<Handle>());
            return read_only_copy(db.local_positions(), {db.frame_count(), db.joint_count(), 3});
          },
          "(frames, joints, 3) float32 metres, relative to each joint's parent (a copy: the "
          "database keeps its pose in groups of four joints)")
      .def_property_readonly(
          "local_rotations",
          [](const py::object& self) {
            const Database& db = db_of(self.cast<Handle>());
            return read_only_copy(db.local_rotations(), {db.frame_count(), db.joint_count(), 4});
          },
          "(frames, joints, 4) float32 unit quaternions (x, y, z, w), relative to each joint's "
          "parent (a copy: the database keeps its pose in groups of four joints)")
      .def_property_readonly(
          "channels", [](const Handle& h) { return channels_of(db_of(h)); },
          "the feature schema: one dict per channel (name, kind, bone, times, "
          "weight, columns as [first, end))")
      .def("with_weights", &with_weights,
           "A copy whose named feature channels have these weights (e.g. "
           "db.with_weights(hips_velocity=2.0)), as if built with them: their columns "
           "rescaled. ValueError on an unknown channel or a weight not finite and > 0.")
      .def("positions", &positions_at, py::arg("frame"),
           "(joints, 3) float32: every joint's global position at this frame (metres)")
      .def("rotations", &rotations_at, py::arg("frame"),
           "(joints, 4) float32: every joint's global rotation at this frame, quaternions (x, "
           "y, z, w)")
      .def_property_readonly(
          "build_report", [](const Handle& h) { return report_of(*h); },
          "what mm.build_database reported (a dict), None for a loaded "
          "database")
      .def("__repr__", &repr);

  m.def("load_database", &load, py::arg("path"),
        "Loads a database file (.mmdb). Raises FileNotFoundError for a missing file and "
        "mm.Error for one that is not a valid database, with the library's message.");
}

}  // namespace mm::python
