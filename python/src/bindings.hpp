#pragma once
// What the Python module's binding files share: the database object, errors, and settings
// given as keyword arguments. The module's Python-facing rules are in python/README.md.

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "mm/controller/controller.hpp"
#include "mm/database/database.hpp"
#include "mm/offline/builder.hpp"
#include "mm/runtime/transform.hpp"

namespace mm::python {

namespace py = pybind11;

// A failure the library reported (its message unchanged): raised in Python as mm.Error, a
// RuntimeError.
struct LibraryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Raises the library's message: FileNotFoundError when `path` does not exist (the library's
// message says why it could not be read), else mm.Error.
[[noreturn]] void raise_for_file(const std::string& message, const std::filesystem::path& path);
// Raises FileNotFoundError with `message` when `path` does not exist; returns otherwise.
void raise_if_missing(const std::string& message, const std::filesystem::path& path);

// mm.Database: one immutable database, shared by the arrays that view it and by the controllers
// made from it.
struct DatabaseHandle {
  std::shared_ptr<const Database> database;
  std::filesystem::path path;  // where it was loaded from or written to
  // What mm.build_database reported; empty for a loaded database.
  std::optional<BuildReport> report;

  // The controllers' shared data, made on first use: a database a controller refuses (no
  // trajectory channels, say) can still be inspected. Raises mm.Error with the reason.
  std::shared_ptr<const ControllerDatabase> controller_database();

 private:
  std::shared_ptr<const ControllerDatabase> controller_database_;
};

// `settings` with each keyword argument set by name (set_controller_setting: True/False become
// "on"/"off", other values their str()), then validated. Raises ValueError with the library's
// message on an unknown name, a bad value or settings out of range.
ControllerSettings settings_from_kwargs(ControllerSettings settings, const py::kwargs& kwargs);

// Every transform's translation as a (count, 3) float32 array, and its rotation as (count, 4)
// quaternions (x, y, z, w): copies, for poses that change or are computed on request.
py::array_t<float> translation_array(std::span<const Transform> transforms);
py::array_t<float> rotation_array(std::span<const Transform> transforms);

void bind_database(py::module_& m);
void bind_controller(py::module_& m);
void bind_runs(py::module_& m);

}  // namespace mm::python
