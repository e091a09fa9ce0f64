// Benchmark driver plumbing. Each bench/bench_<module>.cpp registers suites with MM_BENCH;
// a suite times its stages and records rows. `meshmorph_bench [--quick] [--json out.json]
// [suite...]` runs natively or in wasm (node); scripts/bench runs both and joins the tables.
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace mm::bench {

struct Row {
  std::string suite;   // e.g. "foundation", "edit"
  std::string mesh;    // mesh name (file stem)
  int vertices = 0;    // size of the mesh the stage ran on
  std::string stage;   // e.g. "eigs k=20"
  double ms = 0;       // median wall time in milliseconds
  std::string peer;    // the figure to beat, with its source ("libigl 8 ms", "paper 001: 4.813 s")
  std::string note;    // extra facts (iterations, error, ...)
};

class Context {
 public:
  bool quick = false;  // smaller meshes / fewer repeats (CI smoke run)
  // Absolute path of a data file: the repo's data/ first, then ../shared/data when present.
  // Returns "" when neither exists (the suite should skip that mesh).
  std::string find_data(const std::string& repo_relative, const std::string& shared_relative = "") const;
  // Times fn `repeats` times (after one warm-up unless repeats == 1) and returns the median ms.
  double time_ms(const std::function<void()>& fn, int repeats = 3) const;
  void add(Row row) { rows.push_back(std::move(row)); }
  std::vector<Row> rows;
};

using SuiteFn = std::function<void(Context&)>;
bool register_suite(const std::string& name, SuiteFn fn);

}  // namespace mm::bench

#define MM_BENCH(name, fn) static const bool mm_bench_##name = ::mm::bench::register_suite(#name, fn)
