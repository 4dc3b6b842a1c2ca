// CPU time of the calling thread, ms, for the benchmarks: on a shared machine wall time
// mostly measures the wait for a core (it varied 2x between runs); this is the work.
#pragma once

#include <time.h>

namespace mono_plane_detection {

inline double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace mono_plane_detection
