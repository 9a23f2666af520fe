// The Python module mm (imported as mm._mm by python/mm/__init__.py).

#include <string>

#include "bindings.hpp"
#include "mm/runtime/assert.hpp"

namespace mm::python {
namespace {

// A broken precondition inside the library raises instead of aborting the interpreter. The
// bindings check their arguments first, so this stays a last line of defence.
struct AssertionFailure : std::logic_error {
  using std::logic_error::logic_error;
};

[[noreturn]] void throw_on_assert(const char* expression, const char* file, int line) {
  throw AssertionFailure(std::string("mm: internal check failed: ") + expression + " (" + file +
                         ":" + std::to_string(line) + ")");
}

}  // namespace

void raise_if_missing(const std::string& message, const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
    throw py::error_already_set();
  }
}

void raise_for_file(const std::string& message, const std::filesystem::path& path) {
  raise_if_missing(message, path);
  throw LibraryError(message);
}

py::array_t<float> translation_array(std::span<const Transform> transforms) {
  py::array_t<float> out({static_cast<py::ssize_t>(transforms.size()), py::ssize_t{3}});
  auto o = out.mutable_unchecked<2>();
  for (size_t j = 0; j < transforms.size(); ++j) {
    for (int k = 0; k < 3; ++k) o(static_cast<py::ssize_t>(j), k) = transforms[j].translation[k];
  }
  return out;
}

py::array_t<float> rotation_array(std::span<const Transform> transforms) {
  py::array_t<float> out({static_cast<py::ssize_t>(transforms.size()), py::ssize_t{4}});
  auto o = out.mutable_unchecked<2>();
  for (size_t j = 0; j < transforms.size(); ++j) {
    const glm::quat& q = transforms[j].rotation;
    const auto row = static_cast<py::ssize_t>(j);
    o(row, 0) = q.x;
    o(row, 1) = q.y;
    o(row, 2) = q.z;
    o(row, 3) = q.w;
  }
  return out;
}

ControllerSettings settings_from_kwargs(ControllerSettings settings, const py::kwargs& kwargs) {
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    std::string text;
    if (py::isinstance<py::bool_>(value)) {
      text = value.cast<bool>() ? "on" : "off";
    } else {
      text = py::str(value);
    }
    if (Status s = set_controller_setting(settings, name, text); !s) {
      throw py::value_error(s.message());
    }
  }
  if (Status s = settings.validate(); !s) throw py::value_error(s.message());
  return settings;
}

}  // namespace mm::python

PYBIND11_MODULE(_mm, m) {
  namespace py = pybind11;
  m.doc() =
      "The motion-matching library: databases, controllers, scripted runs and their metrics "
      "(python/README.md).";
  py::register_exception<mm::python::LibraryError>(m, "Error", PyExc_RuntimeError);
  py::register_exception<mm::python::AssertionFailure>(m, "InternalError", PyExc_RuntimeError);
  mm::set_assert_handler(&mm::python::throw_on_assert);
  mm::python::bind_database(m);
  mm::python::bind_controller(m);
  mm::python::bind_runs(m);
}
