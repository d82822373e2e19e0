#include "borrowed_buffer.h"

#include <cctype>
#include <utility>

namespace py = pybind11;

namespace lantern_python {
namespace {

// The dtype as the user knows it (NumPy's name when there is one), for messages.
std::string dtype_text(py::handle object, const std::string &fallback) {
  if (py::hasattr(object, "dtype")) return py::str(object.attr("dtype"));
  return fallback;
}

bool native_order(char order) {
#if PY_LITTLE_ENDIAN
  return order != '>' && order != '!';
#else
  return order != '<';
#endif
}

// Maps (kind letter as in NumPy's typestr, item size) to a Lantern datatype, or throws naming
// the field. `kind_letter`: 'f' float, 'i' signed integer, anything else unsupported.
lantern_datatype element_type(char kind_letter, int64_t itemsize, char order,
                              const std::string &name, ElementKind want, const std::string &dtype) {
  const char *wanted = want == ElementKind::kReal ? "float32 or float64" : "int32 or int64";
  lantern_datatype t = LANTERN_TYPE_NONE;
  if (want == ElementKind::kReal && kind_letter == 'f')
    t = itemsize == 4 ? LANTERN_FLOAT32 : itemsize == 8 ? LANTERN_FLOAT64 : LANTERN_TYPE_NONE;
  if (want == ElementKind::kInteger && kind_letter == 'i')
    t = itemsize == 4 ? LANTERN_INT32 : itemsize == 8 ? LANTERN_INT64 : LANTERN_TYPE_NONE;
  if (t == LANTERN_TYPE_NONE)
    throw py::value_error(name + ": dtype " + dtype + " is not supported; give " + wanted +
                          " (Lantern borrows the array and never converts it)");
  if (!native_order(order))
    throw py::value_error(
        name + ": dtype " + dtype +
        " has non-native byte order; Lantern reads the caller's memory in place "
        "and cannot byte-swap it (convert with a.astype(a.dtype.newbyteorder('=')))");
  return t;
}

// PEP 3118 format ("d", "<f", "=q", ...) -> NumPy-style kind letter and byte order.
std::pair<char, char> parse_format(const char *format) {
  std::string f = format ? format : "B";
  char order = '@';
  if (!f.empty() && std::string("@=<>!").find(f[0]) != std::string::npos) {
    order = f[0];
    f.erase(0, 1);
  }
  if (f.size() != 1) return {'?', order};  // structured or repeated: not one plain element
  switch (f[0]) {
    case 'f':
    case 'd':
      return {'f', order};
    case 'b':
    case 'h':
    case 'i':
    case 'l':
    case 'q':
    case 'n':
      return {'i', order};
    default:
      return {'?', order};
  }
}

// The byte strides of a C-contiguous array of this shape.
std::vector<int64_t> contiguous_strides(const std::vector<int64_t> &shape, int64_t itemsize) {
  std::vector<int64_t> strides(shape.size(), itemsize);
  for (size_t axis = shape.size(); axis-- > 1;) strides[axis - 1] = strides[axis] * shape[axis];
  return strides;
}

}  // namespace

BorrowedBuffer BorrowedBuffer::borrow(py::handle object, const std::string &name,
                                      ElementKind kind) {
  auto exported = std::make_unique<BufferExport>();
  if (PyObject_GetBuffer(object.ptr(), &exported->view, PyBUF_RECORDS_RO) == 0) {
    exported->held = true;
    return from_buffer_protocol(object, name, kind, std::move(exported));
  }
  PyErr_Clear();
  if (py::hasattr(object, "__array_interface__")) return from_array_interface(object, name, kind);
  throw py::value_error(name + ": cannot borrow a " +
                        std::string(py::str(object.get_type().attr("__name__"))) +
                        " (it has neither the buffer protocol nor __array_interface__; give a "
                        "NumPy array or a memoryview)");
}

BorrowedBuffer BorrowedBuffer::from_buffer_protocol(py::handle object, const std::string &name,
                                                    ElementKind kind,
                                                    std::unique_ptr<BufferExport> exported) {
  const Py_buffer *view = &exported->view;
  BorrowedBuffer b;
  b.name_ = name;
  b.owner_ = py::reinterpret_borrow<py::object>(object);
  const auto [letter, order] = parse_format(view->format);
  const std::string format = view->format ? view->format : "B";
  b.type_ = element_type(letter, view->itemsize, order, name, kind,
                         dtype_text(object, "with format '" + format + "'"));
  b.itemsize_ = view->itemsize;
  b.data_ = static_cast<const char *>(view->buf);
  if (view->ndim == 0) {      // a 0-d array (a NumPy scalar's buffer): no axes at all
  } else if (!view->shape) {  // allowed for one-dimensional buffers: len bytes of items
    b.shape_.push_back(view->len / view->itemsize);
  } else {
    b.shape_.assign(view->shape, view->shape + view->ndim);
  }
  if (view->strides) {
    b.strides_.assign(view->strides, view->strides + b.shape_.size());
  } else {  // some exporters (ctypes) leave strides out of C-contiguous buffers
    b.strides_ = contiguous_strides(b.shape_, b.itemsize_);
  }
  b.export_ = std::move(exported);
  return b;
}

BorrowedBuffer BorrowedBuffer::from_array_interface(py::handle object, const std::string &name,
                                                    ElementKind kind) {
  try {
    return read_array_interface(object, name, kind);
  } catch (const py::cast_error &e) {
    // A field of the wrong type (a shape that is not a tuple of ints, an integer too large for
    // int64): pybind11 would raise RuntimeError with its own words.
    throw py::value_error(name + ": __array_interface__ is malformed (" + e.what() + ")");
  }
}

BorrowedBuffer BorrowedBuffer::read_array_interface(py::handle object, const std::string &name,
                                                    ElementKind kind) {
  const py::dict ai = object.attr("__array_interface__");
  BorrowedBuffer b;
  b.name_ = name;
  b.owner_ = py::reinterpret_borrow<py::object>(object);
  const std::string typestr = py::str(ai["typestr"]);
  // "<f8": byte order, kind, item size in bytes (digits; NumPy's largest is 64).
  const std::string digits = typestr.size() >= 3 ? typestr.substr(2) : "";
  if (digits.empty() || digits.size() > 3 ||
      digits.find_first_not_of("0123456789") != std::string::npos)
    throw py::value_error(name + ": __array_interface__ typestr '" + typestr + "' is malformed");
  b.itemsize_ = std::stoll(digits);
  b.type_ = element_type(typestr[1], b.itemsize_, typestr[0], name, kind,
                         dtype_text(object, "'" + typestr + "'"));
  if (!ai.contains("data") || !py::isinstance<py::tuple>(ai["data"]))
    throw py::value_error(name +
                          ": __array_interface__ without a (pointer, read-only) data tuple cannot "
                          "be borrowed");
  b.data_ = reinterpret_cast<const char *>(py::cast<uintptr_t>(py::tuple(ai["data"])[0]));
  for (const auto &extent : py::tuple(ai["shape"])) b.shape_.push_back(py::cast<int64_t>(extent));
  if (ai.contains("strides") && !ai["strides"].is_none()) {
    for (const auto &s : py::tuple(ai["strides"])) b.strides_.push_back(py::cast<int64_t>(s));
    // The publish reads one stride per axis of the shape: fewer read past the list's end.
    if (b.strides_.size() != b.shape_.size())
      throw py::value_error(name + ": __array_interface__ has " +
                            std::to_string(b.strides_.size()) + " strides for " +
                            std::to_string(b.shape_.size()) + " axes");
  } else {  // None: C-contiguous
    b.strides_ = contiguous_strides(b.shape_, b.itemsize_);
  }
  return b;
}

}  // namespace lantern_python
