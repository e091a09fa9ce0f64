#include "common/threads.h"

#include <atomic>
#include <cstdlib>
#include <thread>

namespace mm {
namespace {

std::atomic<int> g_override{0};

int default_threads() {
#if defined(__EMSCRIPTEN__)
  return 1;
#else
  if (const char* e = std::getenv("MM_THREADS")) {
    char* end = nullptr;
    const long n = std::strtol(e, &end, 10);
    if (end != e && *end == '\0' && n >= 1 && n <= 1024) return static_cast<int>(n);
  }
  const unsigned hw = std::thread::hardware_concurrency();
  return hw >= 1 ? static_cast<int>(hw) : 1;
#endif
}

}  // namespace

int max_threads() {
  static const int d = default_threads();
#if defined(__EMSCRIPTEN__)
  return d;  // 1: no threads in this build, whatever was asked
#else
  const int o = g_override.load();
  return o >= 1 ? o : d;
#endif
}

void set_max_threads(int n) { g_override.store(n >= 1 ? n : 0); }

}  // namespace mm
