// `meshmorph options [JOB] [--json]`: the options schema of every job (app/*_job.h) — the same
// description the CLI flags, the wasm bindings and the page's options panels are generated from.
#include <iostream>

#include "app/jobs.h"
#include "cli.h"

namespace mm::cli {
namespace {

int run_options(const std::vector<std::string>& argv) {
  Args args;
  Status s = args.parse(argv, {"help", "json"});
  if (!s.ok()) return report("options", s);
  if (args.has("help") || args.positional().size() > 1) {
    std::cout << "usage: meshmorph options [JOB] [--json]   (JOB: " << app::job_names() << ")\n"
                 "  Lists each job's options with defaults, ranges and help; --json prints the schema\n"
                 "  the page builds its options panels from ({\"jobs\": [...]}).\n";
    return args.has("help") ? 0 : 2;
  }
  const bool json = args.has("json");
  args.get("json");
  const std::string only = args.positional().empty() ? "" : args.positional()[0];
  bool found = only.empty();
  std::string out;
  for (const app::JobSchema& j : app::job_schemas()) {
    if (!only.empty() && j.name != only) continue;
    found = true;
    if (json) out += (out.empty() ? "" : ",\n") + j.json;
    else out += j.name + ":\n" + j.help;
  }
  if (!found) return report("options", Status::error(StatusCode::InvalidArgument, "no job named '" + only.substr(0, 40) + "' (" + app::job_names() + ")"));
  std::cout << (json ? "{\"jobs\": [" + out + "]}\n" : out);
  return 0;
}

}  // namespace

MM_COMMAND(options, "list every job's options (defaults, ranges, help); --json for the schema", run_options);

}  // namespace mm::cli
