#include "core/dump/collective_calls.h"

#include "core/common/collective_status.h"

namespace lantern {

void CollectiveCalls::settle() {
  const Status local =
      pending_.empty() ? Status() : Status(StatusCode::kIo, std::exchange(pending_, {}));
  const Status agreed = agree_on_status(comm_, local);
  if (!agreed.ok()) throw Hdf5Error(agreed.message);
}

}  // namespace lantern
