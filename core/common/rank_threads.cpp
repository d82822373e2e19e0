#include "core/common/rank_threads.h"

#include <sched.h>

#include <cstdlib>
#include <cstring>

namespace lantern {

int default_thread_count() {
  // OMP_NUM_THREADS may be a list (nested levels): its first entry is this level's count.
  if (const char *omp = std::getenv("OMP_NUM_THREADS"); omp && *omp) {
    char *end = nullptr;
    const long n = std::strtol(omp, &end, 10);
    if (end != omp && (*end == '\0' || *end == ',') && n > 0) return int(std::min(n, 1024L));
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return n;
  }
  return 1;
}

}  // namespace lantern
