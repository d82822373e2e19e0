// lantern.Error: the exception the Python module raises for every failed C API call. A subclass
// of RuntimeError carrying .status (the lantern_status as an int), .status_name
// ("LANTERN_ERR_CONFIG") and .message (lantern_error_message()); str(e) joins the three.
//
// Thread-safety: call with the GIL held. The type object lives as long as the module.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "lantern/lantern.h"

namespace lantern_python {

// Creates lantern.Error and adds it to the module; call once, from the module's init.
void define_error(pybind11::module_ &module);

// The status's name, e.g. "LANTERN_ERR_IO" (from lantern_status_string).
std::string status_name(lantern_status status);

// Raises lantern.Error for `status` with `message` (throws pybind11::error_already_set).
[[noreturn]] void raise_error(lantern_status status, const std::string &message);

}  // namespace lantern_python
