// meshmorph: command-line front end of the MeshMorph core. `meshmorph --help` lists commands.
#include <iostream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "cli.h"

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Big meshes allocate and free arrays of tens of MB at every stage (load, weld, validate). By
  // default glibc returns freed heap memory to the system, and the next array faults every page
  // in again: on a 1M-vertex mesh a third of `meshmorph info` was page faults (docs/bench.md, "Loading at scale").
  // Keep freed memory for reuse, and grow the heap in larger steps.
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  mallopt(M_TOP_PAD, 64 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
#endif
  const auto& cmds = mm::cli::commands();
  const std::string first = argc > 1 ? argv[1] : "--help";
  if (first == "--help" || first == "-h" || first == "help") {
    std::cout << "usage: meshmorph <command> [options]   (meshmorph <command> --help for details)\n\ncommands:\n";
    for (const auto& [name, c] : cmds) std::cout << "  " << name << std::string(12 - std::min<size_t>(11, name.size()), ' ') << c.summary << "\n";
    return argc > 1 ? 0 : 2;
  }
  auto it = cmds.find(first);
  if (it == cmds.end()) {
    std::cerr << "meshmorph: unknown command '" << first << "' (see meshmorph --help)\n";
    return 2;
  }
  return it->second.run(std::vector<std::string>(argv + 2, argv + argc));
}
