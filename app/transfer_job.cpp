#include "app/transfer_job.h"

#include <cstdio>

#include "io/asset.h"
#include "io/landmarks_file.h"

namespace mm::app {

const OptionSchema<PoseTransferOptions>& transfer_options() {
  using O = PoseTransferOptions;
  static const OptionSchema<O> schema = [] {
    OptionSchema<O> s("transfer", "give a mesh the pose of another (spectral pose transfer, paper 000)");
    s.choice<TransferMethod>("method", [](O& o) -> TransferMethod& { return o.method; },
                             {{"yin", TransferMethod::Yin}, {"kovnatsky", TransferMethod::Kovnatsky},
                              {"levy", TransferMethod::Levy}},
                             "yin: the paper (cage subspace); kovnatsky / levy: coefficient-swap baselines");
    s.number("lambda1", [](O& o) -> double& { return o.solver.lambda1; }, 0, kUnbounded,
             "λ₁, weight of the cage Laplacian-coordinate term (Eq. 12)");
    s.number("lambda2", [](O& o) -> double& { return o.solver.lambda2; }, 0, kUnbounded,
             "λ₂, weight of the scale penalty (Eq. 12)");
    s.integer("num_low_frequencies", [](O& o) -> int& { return o.num_low_frequencies; }, 0, 100,
              "K, low-frequency coefficients 0..K transferred (Sec. 4.2)");
    s.integer("num_eigenpairs", [](O& o) -> int& { return o.num_eigenpairs; }, 2, 500,
              "eigenpairs per mesh combined into the coupled bases");
    s.integer("num_coupled", [](O& o) -> int& { return o.coupling.num_coupled; }, 1, 500,
              "coupled basis functions (≥ K+1)");
    s.number("mu", [](O& o) -> double& { return o.coupling.mu; }, 0, kUnbounded, "μ, weight of the coupling term");
    s.integer("cage_vertices", [](O& o) -> int& { return o.cage.target_vertices; }, 8, 100000,
              "size of the automatic cage (Table 1: 166-520)");
    s.integer("cage_resolution", [](O& o) -> int& { return o.cage.resolution; }, 8, 1024,
              "offset grid cells along the longest side for the automatic cage");
    s.integer("max_iterations", [](O& o) -> int& { return o.solver.max_iterations; }, 1, 10000,
              "re-linearizations of the cage solve");
    s.number("tolerance", [](O& o) -> double& { return o.solver.tolerance; }, 0, 1,
             "stop when no cage vertex moves more than this × cage diagonal");
    s.choice<TransferPlacement>("placement", [](O& o) -> TransferPlacement& { return o.placement; },
                                {{"reference", TransferPlacement::Reference}, {"source", TransferPlacement::Source}},
                                "where the result is centred");
    return s;
  }();
  return schema;
}

TransferJobResult run_transfer_job(const TransferJobFiles& files, const PoseTransferOptions& options,
                                   const Progress& progress) {
  TransferJobResult r;
  if (Status s = io::check_output_path(files.out); !s.ok()) return {s};
  if (!files.cage_out.empty())
    if (Status s = io::check_output_path(files.cage_out); !s.ok()) return {s};
  const io::LoadResult ref = io::load_asset(files.reference);
  if (!ref.status.ok()) return {ref.status};
  const io::LoadResult src = io::load_asset(files.source);
  if (!src.status.ok()) return {src.status};
  std::vector<LandmarkPair> pairs;
  if (!files.landmarks.empty())
    if (Status s = io::read_landmarks(files.landmarks, &pairs); !s.ok()) return {s};
  r.landmark_pairs = static_cast<int>(pairs.size());
  Mesh cage;
  if (!files.cage.empty()) {
    const io::LoadResult c = io::load_asset(files.cage);
    if (!c.status.ok()) return {c.status};
    cage = c.asset.mesh();
  }
  r.transfer = pose_transfer(ref.asset.mesh(), src.asset.mesh(), pairs, options, progress,
                             files.cage.empty() ? nullptr : &cage);
  if (!(r.status = r.transfer.status).ok()) return r;
  if (!(r.status = io::save_asset(src.asset, r.transfer.V, files.out)).ok()) return r;
  if (!files.cage_out.empty() && r.transfer.cage_deformed.rows() > 0)
    r.status = io::save_mesh(files.cage_out, r.transfer.cage_deformed, r.transfer.cage_faces);
  return r;
}

std::string transfer_summary(const TransferJobResult& r, const PoseTransferOptions& options) {
  const PoseTransferResult& t = r.transfer;
  char buf[512];
  std::string s;
  std::snprintf(buf, sizeof buf, "transfer (%s): %d vertices, %zu landmarks, Γ dominance %.2f",
                transfer_method_name(options.method), int(t.V.rows()), t.landmarks.size(), t.gamma_dominance);
  s += buf;
  if (options.method == TransferMethod::Yin) {
    std::snprintf(buf, sizeof buf, ", cage %d vertices, %d iterations%s", int(t.cage_rest.rows()), t.iterations,
                  t.converged ? "" : " (limit)");
    s += buf;
  }
  std::snprintf(buf, sizeof buf,
                "\n  time: eigenbases %.0f ms, coupling %.0f ms, cage %.0f ms, MVC %.0f ms, optimisation %.0f ms, total %.0f ms\n",
                t.ms.eigenbases, t.ms.coupling, t.ms.cage, t.ms.mvc, t.ms.optimisation, t.ms.total);
  return s + buf;
}

}  // namespace mm::app
