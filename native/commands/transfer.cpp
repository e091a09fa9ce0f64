// `meshmorph transfer` (spectral pose transfer, paper 000) and `meshmorph compare` (metrics).
#include <cstdio>
#include <iostream>


#include "cli.h"
#include "io/asset.h"
#include "metrics/transfer_metrics.h"
#include "app/transfer_job.h"

namespace {

using namespace mm;

const char* kTransferUsage =
    "usage: meshmorph transfer --reference R --source S --out OUT [options]\n"
    "  Gives the source mesh the pose of the reference mesh, keeping the source's details\n"
    "  (Yin et al. 2015, spectral pose transfer).\n"
    "  --landmarks L.json   landmark pairs {\"pairs\": [[reference_vertex, source_vertex], ...]};\n"
    "                       required when the meshes have different connectivity\n"
    "  --cage C             closed cage around the source (default: automatic)\n"
    "  --cage-out FILE      also write the deformed cage\n"
    "  --parts P.json|auto  hierarchical part transfer (paper 000 Sec. 4.3): part pairs from a file\n"
    "                       (core/io/parts_file.h) or proposed where the pose disagrees most\n"
    "  --parts-out FILE     write the part pairs used (without --parts: the proposals)\n"
    "options (app/transfer_job.h):\n";

int run_transfer(const std::vector<std::string>& argv) {
  const auto& schema = app::transfer_options();
  cli::Args args;
  Status s = args.parse(argv, {"help"});
  if (!s.ok()) return cli::report("transfer", s);
  if (args.has("help")) {
    std::cout << kTransferUsage << schema.help() << "part options (with --parts):\n" << app::transfer_part_options().help();
    return 0;
  }
  if (!args.has("reference") || !args.has("source") || !args.has("out")) {
    std::cerr << kTransferUsage << schema.help();
    return cli::report("transfer", Status::error(StatusCode::InvalidArgument, "--reference, --source and --out are required"));
  }
  PoseTransferOptions opt;
  if (!(s = cli::read_options(args, schema, &opt)).ok()) return cli::report("transfer", s);
  PartTransferOptions part_opt;
  if (!(s = cli::read_options(args, app::transfer_part_options(), &part_opt)).ok()) return cli::report("transfer", s);
  app::TransferJobFiles files;
  files.reference = args.get("reference");
  files.source = args.get("source");
  files.out = args.get("out");
  files.landmarks = args.get("landmarks");
  files.cage = args.get("cage");
  files.cage_out = args.get("cage-out");
  files.parts = args.get("parts");
  files.parts_out = args.get("parts-out");
  if (!(s = cli::check_unused(args)).ok()) return cli::report("transfer", s);
  const app::TransferJobResult r = app::run_transfer_job(files, opt, part_opt, cli::terminal_progress());
  if (!r.status.ok()) return cli::report("transfer", r.status);
  std::printf("%swrote %s\n", app::transfer_summary(r, opt).c_str(), files.out.c_str());
  return 0;
}

int run_compare(const std::vector<std::string>& argv) {
  cli::Args args;
  Status s = args.parse(argv, {"help"});
  if (!s.ok()) return cli::report("compare", s);
  if (args.has("help") || args.positional().size() != 2) {
    std::cout << "usage: meshmorph compare A B\n"
                 "  Per-vertex comparison of two meshes with the same vertex order (B is the reference:\n"
                 "  ground truth or source). Prints the vertex error relative to B's bbox diagonal\n"
                 "  (mean, max), the mean change of Laplacian-coordinate magnitude, edge-length distortion\n"
                 "  and locally flipped faces (core/metrics/transfer_metrics.h).\n";
    return args.has("help") ? 0 : 2;
  }
  const io::LoadResult a = io::load_asset(args.positional()[0]);
  if (!a.status.ok()) return cli::report("compare", a.status);
  const io::LoadResult b = io::load_asset(args.positional()[1]);
  if (!b.status.ok()) return cli::report("compare", b.status);
  const Mesh ma = a.asset.mesh(), mb = b.asset.mesh();
  const TransferMetrics m = transfer_metrics(ma.V, mb.V, mb.F);
  if (!m.status.ok()) return cli::report("compare", m.status);
  std::printf("vertex error / bbox diagonal: mean %.6f, max %.6f\n", m.vertex_error_mean, m.vertex_error_max);
  std::printf("Laplacian-coordinate magnitude change: %.6f\n", m.laplacian_change);
  std::printf("edge-length distortion: mean %.6f, max %.6f\n", m.edge_distortion_mean, m.edge_distortion_max);
  std::printf("flipped faces: %d\n", m.flipped_faces);
  if (m.collapsed_faces > 0) std::printf("collapsed faces: %d (below 1/1000 of their area, not flipped)\n", m.collapsed_faces);
  return 0;
}

}  // namespace

MM_COMMAND(transfer, "give a mesh the pose of another (spectral pose transfer)", run_transfer);
MM_COMMAND(compare, "compare two meshes with the same vertex order (pose error, detail metrics)", run_compare);
