// RAII ownership of HDF5 identifiers (hid_t), and HDF5 errors turned into messages.
//
// Every HDF5 object Lantern opens is held by an H5Handle, so an early return or an exception
// closes it. HDF5's automatic error printing is switched off (silence_hdf5_errors); a failed call
// becomes a Hdf5Error whose message says what Lantern was doing and what HDF5 reported.
#pragma once

#include <hdf5.h>

#include <stdexcept>
#include <string>
#include <utility>

namespace lantern {

// Owns one hid_t and closes it with the matching H5?close function.
class H5Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  H5Handle() = default;
  H5Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  ~H5Handle() { reset(); }
  H5Handle(H5Handle &&o) noexcept : id_(std::exchange(o.id_, -1)), close_(o.close_) {}
  H5Handle &operator=(H5Handle &&o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, -1);
      close_ = o.close_;
    }
    return *this;
  }
  H5Handle(const H5Handle &) = delete;
  H5Handle &operator=(const H5Handle &) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = -1;
  }

 private:
  hid_t id_ = -1;
  Closer close_ = nullptr;
};

// A failed HDF5 call (or an H5MD structure that is not what Lantern expects). Internal to the
// dump stage and the readers: their public functions catch it and return a message.
class Hdf5Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Turns off HDF5's printing of error stacks to stderr (process-wide; idempotent). Lantern reports
// HDF5 failures through its own messages instead.
void silence_hdf5_errors();

// The most specific description on HDF5's current error stack (e.g. "truncated file: eof = ..."),
// or "" when the stack is empty.
std::string hdf5_error_detail();

// Throws Hdf5Error("<what>: <HDF5 detail>") when id (or a herr_t) is negative; returns id.
hid_t h5_check(hid_t id, const std::string &what);

// Convenience owners for the common object kinds; each checks the id first.
inline H5Handle own_file(hid_t id, const std::string &what) {
  return {h5_check(id, what), H5Fclose};
}
inline H5Handle own_group(hid_t id, const std::string &what) {
  return {h5_check(id, what), H5Gclose};
}
inline H5Handle own_dataset(hid_t id, const std::string &what) {
  return {h5_check(id, what), H5Dclose};
}
inline H5Handle own_space(hid_t id, const std::string &what) {
  return {h5_check(id, what), H5Sclose};
}
inline H5Handle own_plist(hid_t id, const std::string &what) {
  return {h5_check(id, what), H5Pclose};
}
inline H5Handle own_attr(hid_t id, const std::string &what) {
  return {h5_check(id, what), H5Aclose};
}
inline H5Handle own_type(hid_t id, const std::string &what) {
  return {h5_check(id, what), H5Tclose};
}

}  // namespace lantern
