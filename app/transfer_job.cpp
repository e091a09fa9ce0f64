#include "app/transfer_job.h"

#include <cstdio>

#include "io/asset.h"
#include "io/landmarks_file.h"
#include "io/parts_file.h"

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
    s.integer("fold_retry_resolution", [](O& o) -> int& { return o.fold_retry_resolution; }, 0, 1024,
              "when the result flips faces or self-intersects more than the inputs together, build the automatic cage again on this finer grid and keep the result with fewer folds (0: off)");
    s.integer("flip_repair_rings", [](O& o) -> int& { return o.flip_repair_rings; }, 0, 64,
              "when the result still flips faces, relax them and this many rings of vertices around them as rigidly as possible towards the source's shape, everything else held (0: off)");
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

const OptionSchema<PartTransferOptions>& transfer_part_options() {
  using O = PartTransferOptions;
  static const OptionSchema<O> schema = [] {
    OptionSchema<O> s("transfer-parts", "hierarchical part transfer (paper 000 Sec. 4.3), with --parts");
    s.integer("part_cage_vertices", [](O& o) -> int& { return o.part_cage_vertices; }, 8, 100000,
              "size of each part's automatic cage");
    s.integer("min_part_vertices", [](O& o) -> int& { return o.min_part_vertices; }, 0, 10000000,
              "butterfly-subdivide a part while it has fewer vertices than this");
    s.integer("max_subdivisions", [](O& o) -> int& { return o.max_subdivisions; }, 0, 3,
              "at most this many butterfly levels per part (paper: once or twice)");
    s.integer("seam_rings", [](O& o) -> int& { return o.seam_rings; }, 1, 50,
              "edge rings on each side of a cut smoothed when a part is glued back");
    s.integer("max_parts", [](O& o) -> int& { return o.max_parts; }, 0, 64, "--parts auto: at most this many parts");
    s.number("min_disagreement", [](O& o) -> double& { return o.min_disagreement; }, 0, kUnbounded,
             "--parts auto: propose parts only where the pose disagreement exceeds this (degrees of local rotation; different connectivity: landmark distance in 1/180 of the diagonal)");
    s.number("neck_ratio", [](O& o) -> double& { return o.neck_ratio; }, 1, kUnbounded,
             "--parts auto: isoline perimeter growth that marks where a limb meets the body");
    s.number("max_part_area", [](O& o) -> double& { return o.max_part_area; }, 0, 1,
             "--parts auto: largest part, as a fraction of the surface area");
    s.integer("proposal_sets", [](O& o) -> int& { return o.proposal_sets; }, 1, 5,
              "--parts auto: part sets tried, cut at more distances from the tips each; the one whose landmarks land closest is kept");
    s.integer("proposal_rounds", [](O& o) -> int& { return o.proposal_rounds; }, 1, 10,
              "--parts auto: rounds of proposals, each on the result of the one before (stops when a round brings the landmarks no closer)");
    s.number("max_seam_dihedral_mean", [](O& o) -> double& { return o.max_seam_dihedral_mean; }, 0, 180,
             "a glued part is rejected when the mean dihedral-angle change across its cut exceeds this (degrees)");
    s.boolean("rigid_when_folded", [](O& o) -> bool& { return o.rigid_when_folded; },
              "a part whose own transfer folds faces is turned rigidly onto its landmarks instead");
    s.boolean("reuse_level_cage", [](O& o) -> bool& { return o.reuse_level_cage; },
              "a part takes the level-1 deformed cage, far cage vertices held (paper 000 Sec. 5), where that cage still encloses it");
    s.number("reused_cage_fixed_weight", [](O& o) -> double& { return o.reused_cage_fixed_weight; }, 0, 1,
             "with --reuse-level-cage: the cage vertices carrying the least of the part's mean-value weight, up to this fraction of it, are held");
    return s;
  }();
  return schema;
}

namespace {
// "rotation", or how a part that was registered rigidly came to be (its transfer folded faces).
std::string rigid_note(const PartReport& p) {
  if (!p.rigid) return "rotation";
  return "rigid (its transfer folded " + std::to_string(p.transfer_flips) + " faces), rotation";
}

// "N flipped faces", and ", M collapsed faces" when some are crushed to a sheet (not flipped).
std::string faulty_faces_text(int flipped, int collapsed) {
  std::string t = std::to_string(flipped) + " flipped faces";
  if (collapsed > 0) t += ", " + std::to_string(collapsed) + " collapsed faces";
  return t;
}
std::string faulty_faces_text(const FoldReport& f) { return faulty_faces_text(f.flipped_faces, f.collapsed_faces); }

// ", level-1 cage (N vertices held)" when the part's transfer reused the level-1 cage.
std::string cage_note(const PartReport& p) {
  return p.cage_reused ? ", level-1 cage (" + std::to_string(p.fixed_cage_vertices) + " vertices held)" : "";
}

TransferJobResult transfer_job_failure(Status s) {
  TransferJobResult r;
  r.status = std::move(s);
  return r;
}
}  // namespace

TransferJobResult run_transfer_job(const TransferJobFiles& files, const PoseTransferOptions& options,
                                   const Progress& progress) {
  return run_transfer_job(files, options, PartTransferOptions{}, progress);
}

TransferJobResult run_transfer_job(const TransferJobFiles& files, const PoseTransferOptions& options,
                                   const PartTransferOptions& part_options, const Progress& progress) {
  TransferJobResult r;
  if (Status s = io::check_output_path(files.out); !s.ok()) return transfer_job_failure(s);
  if (!files.cage_out.empty())
    if (Status s = io::check_output_path(files.cage_out); !s.ok()) return transfer_job_failure(s);
  if (!files.parts_out.empty())
    if (Status s = io::check_output_path(files.parts_out); !s.ok()) return transfer_job_failure(s);
  PartsSpec spec;
  const bool auto_parts = files.parts == "auto";
  if (!files.parts.empty() && !auto_parts)
    if (Status s = io::read_parts(files.parts, &spec); !s.ok()) return transfer_job_failure(s);
  if (!files.parts.empty() && options.method != TransferMethod::Yin)
    return transfer_job_failure(Status::error(StatusCode::InvalidArgument, "--parts needs --method yin (the paper's method)"));
  const io::LoadResult ref = io::load_asset(files.reference);
  if (!ref.status.ok()) return transfer_job_failure(ref.status);
  const io::LoadResult src = io::load_asset(files.source);
  if (!src.status.ok()) return transfer_job_failure(src.status);
  std::vector<LandmarkPair> pairs;
  if (!files.landmarks.empty())
    if (Status s = io::read_landmarks(files.landmarks, &pairs); !s.ok()) return transfer_job_failure(s);
  r.landmark_pairs = static_cast<int>(pairs.size());
  Mesh cage;
  if (!files.cage.empty()) {
    const io::LoadResult c = io::load_asset(files.cage);
    if (!c.status.ok()) return transfer_job_failure(c.status);
    cage = c.asset.mesh();
  }
  const Mesh reference = ref.asset.mesh(), source = src.asset.mesh();
  Eigen::MatrixXd result;
  if (!files.parts.empty()) {
    if (!files.cage.empty())
      return transfer_job_failure(Status::error(StatusCode::InvalidArgument, "--cage is not supported with --parts (each part gets its own cage)"));
    PartTransferOptions po = part_options;
    po.transfer = options;
    r.parts = part_transfer(reference, source, pairs, auto_parts ? nullptr : &spec, po, progress);
    if (!(r.status = r.parts.status).ok()) return r;
    r.hierarchical = true;
    r.transfer = r.parts.level1;
    r.folds = r.parts.folds;
    result = r.parts.V;
  } else {
    r.transfer = pose_transfer(reference, source, pairs, options, progress, files.cage.empty() ? nullptr : &cage);
    if (!(r.status = r.transfer.status).ok()) return r;
    result = r.transfer.V;
    r.folds = r.transfer.fold_retry.checked ? r.transfer.folds : fold_report(reference, source, result);
    if (!files.parts_out.empty()) {
      PartTransferOptions po = part_options;
      po.transfer = options;
      r.parts.parts = propose_parts(reference, source, result, r.transfer.landmarks, po, &r.parts.disagreement);
    }
  }
  if (!(r.status = io::save_asset(src.asset, result, files.out)).ok()) return r;
  if (!files.parts_out.empty())
    if (!(r.status = io::write_parts(files.parts_out, r.parts.parts,
                                     "part pairs of meshmorph transfer: reference " + files.reference + ", source " +
                                         files.source))
             .ok())
      return r;
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
  s += buf;
  const FoldRetry& retry = r.hierarchical ? r.parts.fold_retry : t.fold_retry;
  if (retry.tried) {
    const FoldReport& a = retry.first;
    std::snprintf(buf, sizeof buf,
                  "  %s on a %d-cell cage grid (the first result had %s, %d self-intersecting pairs against %d in the inputs): %s, %.0f ms\n",
                  r.hierarchical ? "level 1 and parts again" : "cage rebuilt", retry.resolution, faulty_faces_text(a).c_str(),
                  a.self_intersections_result, a.self_intersections_reference + a.self_intersections_source,
                  retry.kept ? "kept" : "not kept (no fewer folds)", retry.ms);
    s += buf;
  }
  const FlipRepair& repair = r.hierarchical ? r.parts.flip_repair : t.flip_repair;
  if (repair.tried) {
    std::snprintf(buf, sizeof buf, "  flip repair: %s, their neighbourhood solved again (%s), %.0f ms\n",
                  faulty_faces_text(repair.flipped_before, repair.collapsed_before).c_str(),
                  repair.kept ? ("kept: " + std::to_string(repair.moved_vertices) + " vertices moved").c_str()
                              : "not kept (no fewer folds)",
                  repair.ms);
    s += buf;
  }
  if (r.hierarchical) {
    size_t kept = 0;
    for (const PartReport& p : r.parts.reports) kept += p.status.ok();
    std::snprintf(buf, sizeof buf, "  parts: %zu part pairs, %zu kept, in %.0f ms (level 1 %.0f ms, total %.0f ms)\n",
                  r.parts.reports.size(), kept, r.parts.ms_parts, r.parts.ms_level1, r.parts.ms_total);
    s += buf;
    if (r.parts.proposals_tried > 1) {
      std::snprintf(buf, sizeof buf,
                    "  automatic parts: %d proposal sets tried (neck windows) in %d round%s, set %d of the first kept: level landmark error %.4f -> %.4f\n",
                    r.parts.proposals_tried, std::max(1, r.parts.proposal_rounds), r.parts.proposal_rounds > 1 ? "s" : "",
                    r.parts.proposal_kept + 1, r.parts.landmark_error_level1, r.parts.landmark_error);
      s += buf;
    }
    for (const PartReport& p : r.parts.reports) {
      // The gate's landmark figures (the level's landmark error before and after gluing), when the
      // part got that far: a part kept or rejected by a hair shows it here.
      char gate[96] = "";
      if (p.landmark_error_before > 0 || p.landmark_error_after > 0)
        std::snprintf(gate, sizeof gate, ", landmark error %.6f -> %.6f", p.landmark_error_before, p.landmark_error_after);
      std::snprintf(buf, sizeof buf,
                    "    level %d%s %s: %d / %d vertices, %d subdivisions, %d landmarks%s, %s %.1f°, seam dihedral change mean %.1f° max %.1f°%s, %.0f ms%s%s\n",
                    p.level, p.round > 1 ? (", round " + std::to_string(p.round)).c_str() : "",
                    p.name.empty() ? "(unnamed)" : p.name.c_str(), p.source_vertices, p.reference_vertices,
                    p.subdivisions, p.landmarks, cage_note(p).c_str(), rigid_note(p).c_str(), p.rotation_degrees, p.seam_dihedral_mean, p.seam_dihedral_max,
                    gate, p.ms, p.status.ok() ? "" : ", skipped: ", p.status.ok() ? "" : p.status.message.c_str());
      s += buf;
    }
    std::snprintf(buf, sizeof buf, "  level 1: %d self-intersecting triangle pairs, %s\n",
                  r.parts.folds_level1.self_intersections_result, faulty_faces_text(r.parts.folds_level1).c_str());
    s += buf;
  } else if (!r.parts.parts.parts.empty()) {
    std::snprintf(buf, sizeof buf, "  proposed %zu part pairs\n", r.parts.parts.parts.size());
    s += buf;
  }
  const FoldReport& f = r.folds;
  std::snprintf(buf, sizeof buf,
                "  folds: %d self-intersecting triangle pairs (reference %d, source %d)%s, %s\n",
                f.self_intersections_result, f.self_intersections_reference, f.self_intersections_source,
                f.new_folds() ? " — more than the inputs together" : "", faulty_faces_text(f).c_str());
  return s + buf;
}

}  // namespace mm::app
