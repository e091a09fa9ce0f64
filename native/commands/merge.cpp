// meshmorph merge / cut — mesh merging (paper 001 Sec. 5, 6) and opening closed meshes for it.
#include <cmath>
#include <iostream>
#include <stdexcept>
#include <string>

#include "app/merge_job.h"
#include "cli.h"

namespace mm::cli {
namespace {

const char* kMergeUsage =
    "usage: meshmorph merge --target T --source S --spec MERGE.json --out OUT [--quiet] [options]\n"
    "  Deforms the source so that its boundary loops land on the target's (key vertex pairs in the\n"
    "  spec), then zips both into one watertight mesh. Configuration-independent by default: the\n"
    "  source's position, orientation and scale do not matter (Fu, Au, Tai 2007, Sec. 5.1).\n"
    "  OUT keeps the target's glTF document (materials, other nodes) when both are glTF.\n"
    "  Spec format: app/merge_job.h and docs/merge.md; the options below can also be given in the\n"
    "  spec's \"options\" object (same names with '_'); flags win over the spec.\n"
    "options (app/merge_job.h):\n";

int run_merge(const std::vector<std::string>& argv) {
  const auto& schema = app::merge_options();
  Args args;
  Status s = args.parse(argv, {"help", "quiet"});
  if (!s.ok()) return report("merge", s);
  if (args.has("help") || !args.positional().empty() || !args.has("target") || !args.has("source") ||
      !args.has("spec") || !args.has("out")) {
    std::cout << kMergeUsage << schema.help();
    return args.has("help") ? 0 : 2;
  }
  app::MergeJobRequest request;
  request.files = {args.get("target"), args.get("source"), args.get("spec"), args.get("out")};
  const bool quiet = args.has("quiet");
  args.get("quiet");
  MergeOptions probe;
  if (!(s = read_options(args, schema, &probe)).ok()) return report("merge", s);
  if (!(s = check_unused(args)).ok()) return report("merge", s);
  request.set_overrides = [&](MergeOptions& o) { return read_options(args, schema, &o); };
  const app::MergeJobResult r = app::run_merge_job(request, terminal_progress());
  if (!r.status.ok()) return report("merge", r.status);
  if (!quiet) std::cout << app::merge_summary(r, request.files.out);
  return 0;
}

const char* kCutUsage =
    "usage: meshmorph cut IN (--plane PX PY PZ NX NY NZ [--keep X Y Z] | --disk VERTEX RADIUS) --out OUT\n"
    "  Opens a closed mesh for merging. --plane keeps the part on the side of the plane (point P,\n"
    "  normal N) where the point --keep lies (default: the side N points to), and of it the piece\n"
    "  nearest that point; faces crossing the plane are clipped. --disk removes the faces within\n"
    "  geodesic distance RADIUS (mesh units) of VERTEX. OUT keeps IN's glTF document.\n";

// Reads `count` numbers following --name (the first is the flag's value, the rest positionals).
Status numbers_after(const std::vector<std::string>& argv, const std::string& name, int count, std::vector<double>* out) {
  for (size_t i = 0; i < argv.size(); ++i) {
    if (argv[i] != "--" + name) continue;
    if (i + static_cast<size_t>(count) >= argv.size())
      return Status::error(StatusCode::InvalidArgument, "--" + name + " needs " + std::to_string(count) + " numbers");
    for (int k = 1; k <= count; ++k) {
      try {
        size_t used = 0;
        const double v = std::stod(argv[i + k], &used);
        if (used != argv[i + k].size() || !std::isfinite(v)) throw std::invalid_argument("x");
        out->push_back(v);
      } catch (const std::exception&) {
        return Status::error(StatusCode::InvalidArgument, "--" + name + " needs " + std::to_string(count) +
                                                              " numbers (got '" + argv[i + k].substr(0, 40) + "')");
      }
    }
    return Status::success();
  }
  return Status::success();
}

int run_cut(const std::vector<std::string>& argv) {
  // Multi-number flags are taken out before the generic parser sees the rest.
  std::vector<double> plane, keep, disk;
  Status s = numbers_after(argv, "plane", 6, &plane);
  if (s.ok()) s = numbers_after(argv, "keep", 3, &keep);
  if (s.ok()) s = numbers_after(argv, "disk", 2, &disk);
  if (!s.ok()) return report("cut", s);
  std::vector<std::string> rest;
  for (size_t i = 0; i < argv.size(); ++i) {
    const int skip = argv[i] == "--plane" ? 6 : argv[i] == "--keep" ? 3 : argv[i] == "--disk" ? 2 : -1;
    if (skip >= 0) {
      i += static_cast<size_t>(skip);
      continue;
    }
    rest.push_back(argv[i]);
  }
  Args args;
  s = args.parse(rest, {"help"});
  if (!s.ok()) return report("cut", s);
  if (args.has("help") || args.positional().size() != 1 || !args.has("out") || (plane.empty() == disk.empty())) {
    std::cout << kCutUsage;
    return args.has("help") ? 0 : 2;
  }
  app::CutJobRequest req;
  req.in = args.positional()[0];
  req.out = args.get("out");
  if (!(s = check_unused(args)).ok()) return report("cut", s);
  req.plane = !plane.empty();
  if (req.plane) {
    req.point = {plane[0], plane[1], plane[2]};
    req.normal = {plane[3], plane[4], plane[5]};
    if (!keep.empty()) {
      req.has_keep = true;
      req.keep = {keep[0], keep[1], keep[2]};
    }
  } else {
    if (disk[0] != static_cast<int>(disk[0]))
      return report("cut", Status::error(StatusCode::InvalidArgument, "--disk VERTEX must be a vertex index"));
    req.disk_vertex = static_cast<int>(disk[0]);
    req.disk_radius = disk[1];
  }
  const app::CutJobResult r = app::run_cut_job(req);
  if (!r.status.ok()) return report("cut", r.status);
  std::cout << "cut: " << r.vertices << " vertices, " << r.faces << " faces, " << r.boundary_loops
            << " boundary loop(s)\n  wrote " << req.out << "\n";
  return 0;
}

}  // namespace

MM_COMMAND(merge, "attach a source mesh to a target along boundary loops (paper 001 Sec. 5)", run_merge);
MM_COMMAND(cut, "open a closed mesh with a plane or a geodesic disk (for merge)", run_cut);

}  // namespace mm::cli
