#include "core/dump/hdf5_handle.h"

namespace lantern {
namespace {

// H5Ewalk2 callback: keeps the description of the innermost frame that has one (the walk goes
// from the innermost call outwards, so the first non-empty description is the root cause).
herr_t keep_first_description(unsigned, const H5E_error2_t *err, void *out) {
  auto *detail = static_cast<std::string *>(out);
  if (detail->empty() && err && err->desc && *err->desc) *detail = err->desc;
  return 0;
}

}  // namespace

void silence_hdf5_errors() {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

std::string hdf5_error_detail() {
  std::string detail;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, keep_first_description, &detail);
  H5Eclear2(H5E_DEFAULT);
  return detail;
}

hid_t h5_check(hid_t id, const std::string &what) {
  if (id >= 0) return id;
  const std::string detail = hdf5_error_detail();
  throw Hdf5Error(detail.empty() ? what : what + " (" + detail + ")");
}

}  // namespace lantern
