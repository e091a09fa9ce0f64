#include "common/process.h"

#if defined(__GLIBC__) && defined(__linux__)
#include <malloc.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>
#endif

namespace mm {

void tune_process_memory(char** argv) {
#if defined(__GLIBC__) && defined(__linux__)
  if (!std::getenv("MM_NO_HUGE_PAGES")) {
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    if (!tunables || !std::strstr(tunables, "glibc.malloc.hugetlb")) {
      const std::string value = tunables && *tunables ? std::string(tunables) + ":glibc.malloc.hugetlb=1"
                                                     : std::string("glibc.malloc.hugetlb=1");
      if (setenv("GLIBC_TUNABLES", value.c_str(), 1) == 0) execv("/proc/self/exe", argv);
      // exec failed (no /proc): go on with 4 KB pages.
    }
  }
  // Big meshes allocate and free arrays of tens of MB at every stage (load, weld, validate). By
  // default glibc returns freed heap memory to the system, and the next array faults every page
  // in again: on a 1M-vertex mesh a third of `meshmorph info` was page faults. Keep freed memory
  // for reuse, and grow the heap in larger steps. Arrays up to 1 GB come from the heap too (not
  // from their own mmap, which is returned at free): the edit precompute's factor alone is 111 MB
  // at 52k vertices, and faulting it in again cost ~60 ms of each precompute (docs/bench.md,
  // forty-second session). glibc 2.36 accepts this value from mallopt.
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  mallopt(M_TOP_PAD, 64 << 20);
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
#else
  (void)argv;
#endif
}

}  // namespace mm
