#pragma once
// OpenEXR decompresses line blocks on its global thread pool, which is empty unless someone sizes it.
#include <ImfThreading.h>

#include <algorithm>
#include <mutex>
#include <thread>

namespace colorlab::verify::detail {

// Grows the pool to the machine's cores once; never shrinks what the host program chose.
inline int exr_threads() {
  static std::once_flag once;
  std::call_once(once, [] {
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (Imf::globalThreadCount() < cores) Imf::setGlobalThreadCount(cores);
  });
  return Imf::globalThreadCount();
}

}  // namespace colorlab::verify::detail
