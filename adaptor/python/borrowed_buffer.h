// A Python object's memory seen through the buffer protocol (PEP 3118) or NumPy's
// __array_interface__, described as pointer, element type, shape and byte strides: what the
// Python module hands lantern_publish, never a copy.
//
// Ownership: a BorrowedBuffer holds a reference to the object and, for the buffer protocol, the
// buffer export itself, so NumPy refuses to resize the array while Lantern borrows it. Both are
// released when the BorrowedBuffer is destroyed. Thread-safety: create and destroy it with the
// GIL held. Units: bytes for strides.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lantern/lantern.h"

namespace lantern_python {

// Which element types a field accepts: real (float32/64) or integer (int32/64).
enum class ElementKind { kReal, kInteger };

class BorrowedBuffer {
 public:
  // Borrows `object` for the field `name`; throws pybind11::value_error naming the field when
  // the memory cannot be borrowed as is (no buffer, unsupported dtype, non-native byte order).
  static BorrowedBuffer borrow(pybind11::handle object, const std::string &name, ElementKind kind);

  const std::string &name() const { return name_; }
  const char *data() const { return data_; }
  lantern_datatype type() const { return type_; }
  int64_t itemsize() const { return itemsize_; }
  const std::vector<int64_t> &shape() const { return shape_; }
  const std::vector<int64_t> &strides() const { return strides_; }  // bytes, per axis

 private:
  // One PEP 3118 export, released on destruction; heap-held so its address never moves.
  struct BufferExport {
    Py_buffer view{};
    bool held = false;
    BufferExport() = default;
    BufferExport(const BufferExport &) = delete;
    BufferExport &operator=(const BufferExport &) = delete;
    ~BufferExport() {
      if (held) PyBuffer_Release(&view);
    }
  };
  static BorrowedBuffer from_buffer_protocol(pybind11::handle object, const std::string &name,
                                             ElementKind kind,
                                             std::unique_ptr<BufferExport> exported);
  static BorrowedBuffer from_array_interface(pybind11::handle object, const std::string &name,
                                             ElementKind kind);
  static BorrowedBuffer read_array_interface(pybind11::handle object, const std::string &name,
                                             ElementKind kind);

  std::string name_;
  pybind11::object owner_;                // keeps the caller's array alive
  std::unique_ptr<BufferExport> export_;  // held buffer export (null for __array_interface__)
  const char *data_ = nullptr;
  lantern_datatype type_ = LANTERN_TYPE_NONE;
  int64_t itemsize_ = 0;
  std::vector<int64_t> shape_, strides_;
};

}  // namespace lantern_python
