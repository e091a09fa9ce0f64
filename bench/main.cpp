// meshmorph_bench: runs the registered suites and prints a table (and optionally JSON rows,
// which scripts/bench.mjs joins across the native and wasm runs).
//   meshmorph_bench [--quick] [--json FILE] [suite ...]
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "common/process.h"
#include "common/threads.h"
#include "bench.h"

namespace mm::bench {

namespace {
std::map<std::string, SuiteFn>& suites() {
  static std::map<std::string, SuiteFn> s;
  return s;
}
}  // namespace

bool register_suite(const std::string& name, SuiteFn fn) {
  suites()[name] = std::move(fn);
  return true;
}

std::string Context::find_data(const std::string& repo_relative, const std::string& shared_relative) const {
  namespace fs = std::filesystem;
  const fs::path root(MM_SOURCE_DIR);
  if (!repo_relative.empty() && fs::exists(root / "data" / repo_relative)) return (root / "data" / repo_relative).string();
  if (!shared_relative.empty()) {
    const fs::path shared = root / ".." / "shared" / "data" / shared_relative;
    if (fs::exists(shared)) return fs::canonical(shared).string();
  }
  return "";
}

double Context::time_ms(const std::function<void()>& fn, int repeats) const {
  if (quick) repeats = 1;
  std::vector<double> t;
  if (repeats > 1) fn();  // warm-up
  for (int r = 0; r < repeats; ++r) {
    const auto a = std::chrono::steady_clock::now();
    fn();
    const auto b = std::chrono::steady_clock::now();
    t.push_back(std::chrono::duration<double, std::milli>(b - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace mm::bench

int main(int argc, char** argv) {
  // The CLI's process settings (huge pages for malloc, freed memory kept), so that the rows are
  // what `meshmorph` runs at; MM_NO_HUGE_PAGES=1 keeps 4 KB pages (common/process.h).
  mm::tune_process_memory(argv);
  using namespace mm::bench;
  Context ctx;
  std::string json_path;
  std::vector<std::string> wanted;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) ctx.quick = true;
    else if (!std::strcmp(argv[i], "--json") && i + 1 < argc) json_path = argv[++i];
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
      // Threads the core may use (common/threads.h): 1 runs every stage in sequence.
      const int n = std::atoi(argv[++i]);
      if (n < 1) {
        std::cerr << "meshmorph_bench: --threads needs a positive count\n";
        return 2;
      }
      mm::set_max_threads(n);
    }
    else if (!std::strcmp(argv[i], "--list")) {
      for (const auto& [name, fn] : suites()) std::cout << name << "\n";
      return 0;
    } else wanted.push_back(argv[i]);
  }
  for (const auto& w : wanted)
    if (!suites().count(w)) {
      std::cerr << "meshmorph_bench: unknown suite '" << w << "' (--list shows them)\n";
      return 2;
    }
  for (const auto& [name, fn] : suites()) {
    if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), name) == wanted.end()) continue;
    std::fprintf(stderr, "running suite %s (%d thread%s)...\n", name.c_str(), mm::max_threads(), mm::max_threads() == 1 ? "" : "s");
    fn(ctx);
  }
  std::printf("%-12s %-22s %8s  %-28s %11s  %-34s %s\n", "suite", "mesh", "#V", "stage", "ms", "peer", "note");
  for (const auto& r : ctx.rows)
    std::printf("%-12s %-22s %8d  %-28s %11.2f  %-34s %s\n", r.suite.c_str(), r.mesh.c_str(), r.vertices,
                r.stage.c_str(), r.ms, r.peer.c_str(), r.note.c_str());
  if (!json_path.empty()) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& r : ctx.rows)
      j.push_back({{"suite", r.suite}, {"mesh", r.mesh}, {"vertices", r.vertices}, {"stage", r.stage},
                   {"ms", r.ms}, {"peer", r.peer}, {"note", r.note}, {"threads", mm::max_threads()}});
    std::ofstream(json_path) << j.dump(1) << "\n";
  }
  return 0;
}
