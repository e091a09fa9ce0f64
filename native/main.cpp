// meshmorph: command-line front end of the MeshMorph core. `meshmorph --help` lists commands.
#include <iostream>

#include "cli.h"
#include "common/process.h"

int main(int argc, char** argv) {
  mm::tune_process_memory(argv);  // huge pages, freed memory kept (core/common/process.h)
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
