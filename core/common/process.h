// Process-wide memory settings for the native programs (the CLI, the bench): called first thing in
// main(). No-ops outside Linux/glibc (and in wasm).
#pragma once

namespace mm {

// Transparent huge pages for malloc, and freed memory kept for reuse. Loading a 1M-vertex mesh
// touches ~300 MB; with 4 KB pages the page faults and TLB misses were the largest single cost
// (`meshmorph info` on the 1M-vertex grid: 1.5–2.1 s wall, 0.55 s of it in the kernel; with huge
// pages 0.47 s; docs/bench.md). glibc reads its tunables only at start, so the program restarts
// itself once (execv of /proc/self/exe with the same argv) with glibc.malloc.hugetlb=1 added to
// GLIBC_TUNABLES; MM_NO_HUGE_PAGES=1 keeps 4 KB pages. The kernel's THP mode "madvise" (Debian's
// default) is what the tunable asks for; "never" makes it a no-op. Returns only in the process that
// goes on (the restarted one, or this one when the restart is off or fails).
void tune_process_memory(char** argv);

}  // namespace mm
