// The compiled part of the Python package `lantern` (lantern/_lantern): Lantern's C API for Python
// codes (NumPy, ASE, LAMMPS's Python interface), borrowing their arrays without copying. The
// package (adaptor/python/lantern/__init__.py) re-exports it. See README.md, "Python".
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "lantern/lantern.h"
#include "python_context.h"
#include "python_error.h"

namespace py = pybind11;
using lantern_python::Context;
using lantern_python::PublishArguments;

PYBIND11_MODULE(_lantern, m) {
  m.doc() =
      "Lantern: in-situ rendering of particle simulations. Context(config, comm=None) opens a "
      "context; publish() borrows NumPy arrays (never copied); execute(step, time) renders on "
      "scheduled steps.";
  m.attr("__version__") = lantern_version();
  lantern_python::define_error(m);
  for (int s = LANTERN_OK; s <= LANTERN_ERR_INTERNAL; ++s) {
    const std::string name = lantern_python::status_name(static_cast<lantern_status>(s));
    m.attr(name.substr(std::string("LANTERN_").size()).c_str()) = s;  // OK, ERR_CONFIG, ...
  }
  m.attr("COMM_WORLD") = LANTERN_COMM_WORLD;

  py::class_<Context>(m, "Context",
                      "An open Lantern context (lantern_open). Use as a context manager or call "
                      "close(); opening, execute() on scheduled steps and close() are collective "
                      "over the communicator.")
      .def(py::init<const py::object &, const py::object &>(), py::arg("config"),
           py::arg("comm") = py::none(),
           "config: YAML text or the path of a YAML file; comm: an mpi4py communicator, a "
           "Fortran handle or None for MPI_COMM_WORLD.")
      .def(
          "publish",
          [](Context &self, py::object position, py::object position_x, py::object position_y,
             py::object position_z, py::object radius, py::object scalar, py::object type,
             py::object id, py::object mask, int64_t mask_bits, py::object bonds,
             py::object bond_type, int64_t ghost_count, std::string bonds_listed) {
            self.publish(PublishArguments{position, position_x, position_y, position_z, radius,
                                          scalar, type, id, mask, mask_bits, bonds, bond_type,
                                          ghost_count, std::move(bonds_listed)});
          },
          py::arg("position") = py::none(), py::kw_only(), py::arg("position_x") = py::none(),
          py::arg("position_y") = py::none(), py::arg("position_z") = py::none(),
          py::arg("radius") = py::none(), py::arg("scalar") = py::none(),
          py::arg("type") = py::none(), py::arg("id") = py::none(), py::arg("mask") = py::none(),
          py::arg("mask_bits") = 0, py::arg("bonds") = py::none(),
          py::arg("bond_type") = py::none(), py::arg("ghost_count") = 0,
          py::arg("bonds_listed") = "once",
          "Borrows this rank's particle arrays until the next publish() or close(), never "
          "copying them: position (n, 3) float32/float64 (any row stride; x, y, z a fixed stride "
          "apart) or position_x/y/z (n,); radius, scalar (n,) float32/float64; type, id, mask "
          "(n,) int32/int64; mask_bits: draw particle i only if mask[i] & mask_bits. Bonds "
          "(drawn by scenes with a bonds: section): bonds (m, 2) int32/int64, each row two "
          "indices into the particle rows (any strides); bond_type (m,) int32/int64; "
          "ghost_count: the last ghost_count rows of every particle array are ghosts, other "
          "ranks' atoms used only as bond ends (never drawn; needs id); bonds_listed: 'once' "
          "(each bond in one rank's list) or 'by_both' (in both atoms' ranks' lists). Any object "
          "with the buffer protocol or __array_interface__. ValueError names an array that "
          "cannot be borrowed as it is; lantern.Error reports what Lantern refused.")
      .def("set_box", &Context::set_box, py::arg("low"), py::arg("high"),
           py::arg("periodic") = py::none(), py::arg("tilt") = py::none(),
           "Records the simulation box (corners low, high; periodic: three bools) for dumps, "
           "the box overlay and the minimum image of bonds along periodic axes. tilt: (xy, xz, "
           "yz) makes it triclinic in LAMMPS's restricted form: edge vectors (lx, 0, 0), "
           "(xy, ly, 0), (xz, yz, lz) from low, l = high - low (reduced box vectors a, b, c: "
           "high = low + (a_x, b_y, c_z), tilt = (b_x, c_x, c_y)).")
      .def("execute", &Context::execute, py::arg("step"), py::arg("time") = 0.0,
           "The simulation reached `step` at `time`: renders on the steps the schedule picks.")
      .def("close", &Context::close, "Flushes outputs and frees the context (collective).")
      .def_property_readonly("closed", &Context::closed)
      .def("published_pointers", &Context::published_pointers,
           "Field name -> address of the memory handed to lantern_publish (for checking that "
           "Lantern reads the caller's own arrays).")
      .def(
          "__enter__", [](Context &self) -> Context & { return self; },
          py::return_value_policy::reference)
      .def("__exit__", [](Context &self, const py::object &type, const py::object &,
                          const py::object &) { return self.exit(type); });

  // Contexts left open are closed at exit, before mpi4py finalizes MPI (Python's atexit
  // handlers run before those registered with Py_AtExit).
  py::module_::import("atexit").attr("register")(py::cpp_function(&Context::close_all));
}
