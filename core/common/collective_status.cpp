#include "core/common/collective_status.h"

#include <vector>

namespace lantern {

Status broadcast_status(MPI_Comm comm, const Status &status, int root) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int header[2] = {int(status.code), int(status.message.size())};
  MPI_Bcast(header, 2, MPI_INT, root, comm);
  std::vector<char> text(size_t(header[1]) + 1, '\0');
  if (rank == root) status.message.copy(text.data(), status.message.size());
  if (header[1] > 0) MPI_Bcast(text.data(), header[1], MPI_CHAR, root, comm);
  return Status(StatusCode(header[0]), std::string(text.data(), size_t(header[1])));
}

Status agree_on_status(MPI_Comm comm, const Status &local) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int mine = local.ok() ? size : rank;
  int first_failure = size;
  MPI_Allreduce(&mine, &first_failure, 1, MPI_INT, MPI_MIN, comm);
  if (first_failure == size) return {};
  return broadcast_status(comm, local, first_failure);
}

}  // namespace lantern
