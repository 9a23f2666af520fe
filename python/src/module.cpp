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
