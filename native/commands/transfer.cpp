// `meshmorph transfer` (spectral pose transfer, paper 000) and `meshmorph compare` (metrics).
#include <cstdio>
#include <iostream>


#include "cli.h"
#include "io/asset.h"
#include "io/landmarks_file.h"
#include "metrics/transfer_metrics.h"
#include "transfer/pose_transfer.h"

namespace {

using namespace mm;

const char* kTransferHelp =
    "usage: meshmorph transfer --reference R --source S --out OUT [options]\n"
    "  Gives the source mesh the pose of the reference mesh, keeping the source's details\n"
    "  (Yin et al. 2015, spectral pose transfer).\n"
    "  --landmarks L.json   landmark pairs {\"pairs\": [[reference_vertex, source_vertex], ...]};\n"
    "                       required when the meshes have different connectivity\n"
    "  --cage C             closed cage around the source (default: automatic)\n"
    "  --method M           yin (default) | kovnatsky | levy\n"
    "  --lambda1 X          cage Laplacian-coordinate weight (default 0.05)\n"
    "  --lambda2 X          scale penalty weight (default 0.05)\n"
    "  --num-low-frequencies K   transferred coefficients 0..K (default 5)\n"
    "  --num-eigenpairs N   eigenpairs per mesh (default 20)\n"
    "  --cage-vertices N    automatic cage size (default 450)\n"
    "  --cage-resolution N  offset grid cells along the longest side for the automatic cage (default 80)\n"
    "  --max-iterations N   re-linearizations of the cage solve (default 50)\n"
    "  --placement P        reference (default) | source: where the result is centred\n"
    "  --cage-out FILE      also write the deformed cage\n";

int run_transfer(const std::vector<std::string>& argv) {
  cli::Args args;
  Status s = args.parse(argv, {"help"});
  if (!s.ok()) return cli::report("transfer", s);
  if (args.has("help")) {
    std::cout << kTransferHelp;
    return 0;
  }
  if (!args.has("reference") || !args.has("source") || !args.has("out")) {
    std::cerr << kTransferHelp;
    return cli::report("transfer", Status::error(StatusCode::InvalidArgument, "--reference, --source and --out are required"));
  }
  PoseTransferOptions opt;
  Status perr;
  opt.solver.lambda1 = args.get_double("lambda1", opt.solver.lambda1, &perr);
  opt.solver.lambda2 = args.get_double("lambda2", opt.solver.lambda2, &perr);
  opt.num_low_frequencies = args.get_int("num-low-frequencies", opt.num_low_frequencies, &perr);
  opt.num_eigenpairs = args.get_int("num-eigenpairs", opt.num_eigenpairs, &perr);
  opt.cage.target_vertices = args.get_int("cage-vertices", opt.cage.target_vertices, &perr);
  opt.cage.resolution = args.get_int("cage-resolution", opt.cage.resolution, &perr);
  opt.solver.max_iterations = args.get_int("max-iterations", opt.solver.max_iterations, &perr);
  if (!perr.ok()) return cli::report("transfer", perr);
  const std::string method = args.get("method", "yin");
  if (!parse_transfer_method(method, &opt.method))
    return cli::report("transfer", Status::error(StatusCode::InvalidArgument, "--method must be yin, kovnatsky or levy"));
  const std::string placement = args.get("placement", "reference");
  if (placement != "reference" && placement != "source")
    return cli::report("transfer", Status::error(StatusCode::InvalidArgument, "--placement must be reference or source"));
  opt.placement = placement == "source" ? TransferPlacement::Source : TransferPlacement::Reference;
  const std::string landmarks_path = args.get("landmarks"), cage_path = args.get("cage"),
                    cage_out = args.get("cage-out"), out_path = args.get("out");
  const io::LoadResult ref = io::load_asset(args.get("reference"));
  if (!ref.status.ok()) return cli::report("transfer", ref.status);
  const io::LoadResult src = io::load_asset(args.get("source"));
  if (!src.status.ok()) return cli::report("transfer", src.status);
  std::vector<LandmarkPair> pairs;
  if (!landmarks_path.empty() && !(s = io::read_landmarks(landmarks_path, &pairs)).ok()) return cli::report("transfer", s);
  Mesh cage;
  if (!cage_path.empty()) {
    const io::LoadResult c = io::load_asset(cage_path);
    if (!c.status.ok()) return cli::report("transfer", c.status);
    cage = c.asset.mesh();
  }
  for (const auto& u : args.unused())
    return cli::report("transfer", Status::error(StatusCode::InvalidArgument, "unknown option --" + u));
  const PoseTransferResult r = pose_transfer(ref.asset.mesh(), src.asset.mesh(), pairs, opt, cli::terminal_progress(),
                                             cage_path.empty() ? nullptr : &cage);
  if (!r.status.ok()) return cli::report("transfer", r.status);
  if (!(s = io::save_asset(src.asset, r.V, out_path)).ok()) return cli::report("transfer", s);
  if (!cage_out.empty() && r.cage_deformed.rows() > 0 &&
      !(s = io::save_mesh(cage_out, r.cage_deformed, r.cage_faces)).ok())
    return cli::report("transfer", s);
  std::printf("transfer (%s): %d vertices, %zu landmarks, Γ dominance %.2f", transfer_method_name(opt.method),
              int(r.V.rows()), r.landmarks.size(), r.gamma_dominance);
  if (opt.method == TransferMethod::Yin)
    std::printf(", cage %d vertices, %d iterations%s", int(r.cage_rest.rows()), r.iterations,
                r.converged ? "" : " (limit)");
  std::printf("\n  time: eigenbases %.0f ms, coupling %.0f ms, cage %.0f ms, MVC %.0f ms, optimisation %.0f ms, total %.0f ms\n",
              r.ms.eigenbases, r.ms.coupling, r.ms.cage, r.ms.mvc, r.ms.optimisation, r.ms.total);
  std::printf("wrote %s\n", out_path.c_str());
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
  return 0;
}

}  // namespace

MM_COMMAND(transfer, "give a mesh the pose of another (spectral pose transfer)", run_transfer);
MM_COMMAND(compare, "compare two meshes with the same vertex order (pose error, detail metrics)", run_compare);
