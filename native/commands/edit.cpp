// meshmorph edit — implicit Laplacian editing (paper 001) driven by a JSON spec.
#include <iostream>

#include "cli.h"
#include "app/edit_job.h"

namespace mm::cli {
namespace {

const char* kEditUsage =
    "usage: meshmorph edit IN --spec EDIT.json --out OUT [--preview-only] [--quiet] [options]\n"
    "  Moves the handles named in the spec and reconstructs the region of interest so that local\n"
    "  details rotate with the surface (Fu, Au, Tai: implicit Laplacian editing with similarity\n"
    "  transformations). OUT keeps the rest of IN's document (same format) or converts by extension.\n"
    "  --preview-only    write the fast first solve (Eq. 7) without shear removal\n"
    "  --quiet           no summary on stdout\n"
    "  Spec format: app/edit_spec.h; examples in data/specs/. The options below can also be given\n"
    "  in the spec's \"options\" object (same names with '_'); flags win over the spec.\n"
    "options (app/edit_job.h):\n";

int run_edit(const std::vector<std::string>& argv) {
  const auto& schema = app::edit_options();
  Args args;
  // The last three were switches before the options schema; they are parsed only to say what
  // replaced them.
  Status s = args.parse(argv, {"help", "preview-only", "quiet", "naive", "keep-size", "scale-features"});
  if (!s.ok()) return report("edit", s);
  const std::pair<const char*, const char*> replaced[] = {
      {"naive", "--method naive"}, {"keep-size", "--features keep"}, {"scale-features", "--features scale"}};
  for (const auto& [old_flag, now] : replaced)
    if (args.has(old_flag))
      return report("edit", Status::error(StatusCode::InvalidArgument,
                                          std::string("--") + old_flag + " is now " + now + " (see meshmorph edit --help)"));
  if (args.has("help") || args.positional().size() != 1 || !args.has("spec") || !args.has("out")) {
    std::cout << kEditUsage << schema.help();
    return args.has("help") ? 0 : 2;
  }
  auto flag = [&](const char* name) {  // reading a switch marks it as used
    if (!args.has(name)) return false;
    args.get(name);
    return true;
  };
  app::EditJobRequest request;
  request.files = {args.positional()[0], args.get("spec"), args.get("out")};
  request.preview_only = flag("preview-only");
  const bool quiet = flag("quiet");
  // Validate the flags now (before loading anything); apply them over the spec's options later.
  app::EditJobOptions probe;
  if (!(s = read_options(args, schema, &probe)).ok()) return report("edit", s);
  if (!(s = check_unused(args)).ok()) return report("edit", s);
  request.set_overrides = [&](app::EditJobOptions& o) { return read_options(args, schema, &o); };
  const app::EditJobResult r = app::run_edit_job(request, terminal_progress());
  if (!r.status.ok()) return report("edit", r.status);
  if (!quiet) std::cout << app::edit_summary(r, request.files.out);
  return 0;
}

}  // namespace

MM_COMMAND(edit, "move handles; details follow (implicit Laplacian editing, paper 001)", run_edit);

}  // namespace mm::cli
