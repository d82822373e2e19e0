// libFuzzer: the Python publish path (lantern.Context.publish and its argument checks in
// adaptor/python) driven from an embedded interpreter. fuzz_python_publish.py turns the bytes into
// arguments; a Python exception other than the expected refusals, a crash or a sanitizer report
// is a finding. The module `lantern` of this build is imported (LANTERN_PYTHON_DIR).
#include <Python.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace {

PyObject *run = nullptr;
PyObject *context = nullptr;

[[noreturn]] void fail(const char *what) {
  std::fprintf(stderr, "fuzz_python_publish: %s\n", what);
  if (PyErr_Occurred()) PyErr_Print();
  __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
  Py_Initialize();
  const std::string setup = std::string("import sys\nsys.path[:0] = ['") + LANTERN_PYTHON_DIR +
                            "', '" + LANTERN_FUZZ_DIR + "']\n";
  if (PyRun_SimpleString(setup.c_str()) != 0) fail("cannot set sys.path");
  PyObject *module = PyImport_ImportModule("fuzz_python_publish");
  if (!module) fail("cannot import fuzz_python_publish.py");
  run = PyObject_GetAttrString(module, "run");
  PyObject *lantern = PyImport_ImportModule("lantern");
  if (!run || !lantern) fail("cannot import lantern");
  PyObject *make = PyObject_GetAttrString(lantern, "Context");
  context =
      PyObject_CallFunction(make, "s",
                            "gl: none\nscenes:\n  - {name: f, width: 8, height: 8, renderer: cpu,\n"
                            "     output: {pattern: '/dev/shm/lantern_fuzz_python_{step}.png'}}\n");
  if (!context) fail("cannot open a context");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  PyObject *bytes =
      PyBytes_FromStringAndSize(reinterpret_cast<const char *>(data), Py_ssize_t(size));
  PyObject *ok = PyObject_CallFunctionObjArgs(run, context, bytes, nullptr);
  Py_DECREF(bytes);
  if (!ok) fail("the harness raised");
  const bool expected = ok == Py_True;
  Py_DECREF(ok);
  if (!expected) fail("unexpected exception (printed above)");
  return 0;
}
