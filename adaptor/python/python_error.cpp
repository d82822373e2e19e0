#include "python_error.h"

namespace py = pybind11;

namespace lantern_python {
namespace {

// Owned by the module (module.Error holds a reference); never freed before it.
PyObject *error_type = nullptr;

}  // namespace

void define_error(py::module_ &module) {
  error_type = PyErr_NewExceptionWithDoc(
      "lantern.Error",
      "A Lantern C API call failed. .status: the lantern_status (int); .status_name: its name "
      "(e.g. 'LANTERN_ERR_CONFIG'); .message: what went wrong, naming the argument or "
      "configuration key at fault.",
      PyExc_RuntimeError, nullptr);
  if (!error_type) throw py::error_already_set();
  module.attr("Error") = py::reinterpret_steal<py::object>(error_type);
}

std::string status_name(lantern_status status) {
  const std::string text = lantern_status_string(status);
  return text.substr(0, text.find(':'));
}

void raise_error(lantern_status status, const std::string &message) {
  const std::string name = status_name(status);
  const py::object type = py::reinterpret_borrow<py::object>(error_type);
  const py::object error = type(name + ": " + message);
  error.attr("status") = static_cast<int>(status);
  error.attr("status_name") = name;
  error.attr("message") = message;
  PyErr_SetObject(error_type, error.ptr());
  throw py::error_already_set();
}

}  // namespace lantern_python
