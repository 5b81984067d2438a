// CPU seconds of the calling thread, for benchmarks that time a peer and dyncull on the same frames and
// report their ratio: the ratio stays meaningful on a loaded machine (every peer runs on one thread).
#pragma once

#include <chrono>

#if defined(__unix__)
#include <time.h>
#endif

namespace dyncull {
namespace bench {

/// CPU seconds of the calling thread; wall time where the thread clock is missing.
inline double cpu_seconds() {
#if defined(__unix__) && defined(CLOCK_THREAD_CPUTIME_ID)
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
#else
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
#endif
}

}  // namespace bench
}  // namespace dyncull
