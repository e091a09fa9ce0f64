#include "transfer/pose_transfer.h"
#include "transfer/flip_repair.h"

#include <chrono>
#include <mutex>
#include <numeric>
#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "cage/mean_value_coordinates.h"
#include "common/threads.h"
#include "metrics/transfer_metrics.h"
#include "mesh/validate.h"
#include "operators/operators.h"
#include "spectral/spectral_basis.h"
#include "spatial/self_intersections.h"

namespace mm {

const char* transfer_method_name(TransferMethod m) {
  switch (m) {
    case TransferMethod::Yin: return "yin";
    case TransferMethod::Kovnatsky: return "kovnatsky";
    case TransferMethod::Levy: return "levy";
  }
  return "yin";
}

bool parse_transfer_method(const std::string& name, TransferMethod* m) {
  if (name == "yin") *m = TransferMethod::Yin;
  else if (name == "kovnatsky") *m = TransferMethod::Kovnatsky;
  else if (name == "levy") *m = TransferMethod::Levy;
  else return false;
  return true;
}

namespace transfer_detail {

double elapsed_ms(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// A mesh centred at its area-weighted centroid and scaled to unit surface area.
struct Normalized {
  Eigen::MatrixXd V;
  Eigen::VectorXd mass;        // lumped areas of the normalized mesh (sum 1)
  Eigen::RowVector3d centroid; // of the input
  double scale = 1;            // sqrt(area of the input): V_input = centroid + scale · V
};

Status normalize(const Mesh& m, const char* which, Normalized* out) {
  const Eigen::VectorXd a = mass_diagonal(m.V, m.F);
  const double area = a.sum();
  if (!(area > 0) || !std::isfinite(area))
    return Status::error(StatusCode::InvalidMesh, std::string(which) + " mesh has zero surface area");
  for (int i = 0; i < a.size(); ++i)
    if (!(a[i] > 0))
      return Status::error(StatusCode::InvalidMesh, std::string(which) + " mesh: vertex " + std::to_string(i) +
                                                        " has zero area (unreferenced vertex or degenerate faces)");
  out->centroid = (a.transpose() * m.V) / area;
  out->scale = std::sqrt(area);
  out->V = (m.V.rowwise() - out->centroid) / out->scale;
  out->mass = a / area;
  return Status::success();
}

}  // namespace transfer_detail

FoldReport fold_report(const FoldReport& inputs, const Mesh& source, const Eigen::MatrixXd& result) {
  FoldReport r = inputs;
  r.self_intersections_result = self_intersections(result, source.F).pairs;
  const TransferMetrics m = transfer_metrics(result, source.V, source.F);
  r.flipped_faces = m.flipped_faces;
  r.collapsed_faces = m.collapsed_faces;
  return r;
}

FoldReport fold_report(const Mesh& reference, const Mesh& source, const Eigen::MatrixXd& result) {
  FoldReport inputs;
  inputs.self_intersections_reference = self_intersections(reference.V, reference.F).pairs;
  inputs.self_intersections_source = self_intersections(source.V, source.F).pairs;
  return fold_report(inputs, source, result);
}

Status repair_transfer_flips(const Mesh& source, int rings, const Progress& progress, Eigen::MatrixXd* result,
                             FoldReport* folds, FlipRepair* record) {
  if (rings <= 0 || folds->faulty_faces() == 0) return Status{};
  FlipRepairOptions o;
  o.rings = rings;
  FlipRepairResult r = repair_flips(source, *result, o, progress);
  record->tried = true;
  record->flipped_before = folds->flipped_faces;
  record->collapsed_before = folds->collapsed_faces;
  record->rounds = r.rounds;
  record->ms = r.ms;
  if (r.status.code == StatusCode::Cancelled) return r.status;
  if (!r.status.ok() || r.faulty_after() >= r.faulty_before()) return Status{};
  const FoldReport repaired = fold_report(*folds, source, r.V);
  if (repaired.violations() < folds->violations()) {
    record->kept = true;
    record->moved_vertices = r.moved_vertices;
    *result = std::move(r.V);
    *folds = repaired;
  }
  return Status{};
}

PoseTransferResult pose_transfer(const Mesh& reference, const Mesh& source, const std::vector<LandmarkPair>& landmarks,
                                 const PoseTransferOptions& opt, const Progress& progress, const Mesh* user_cage) {
  using namespace transfer_detail;
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  PoseTransferResult out;
  const int K = opt.num_low_frequencies;
  const int kp = opt.num_eigenpairs;
  if (K < 0 || kp < K + 1 || opt.coupling.num_coupled < K + 1 || opt.coupling.num_coupled > kp) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "need 0 <= K < num_coupled <= num_eigenpairs (K = " + std::to_string(K) +
                                   ", num_coupled = " + std::to_string(opt.coupling.num_coupled) +
                                   ", num_eigenpairs = " + std::to_string(kp) + ")");
    return out;
  }
  for (const auto& [mesh, name] : {std::pair<const Mesh*, const char*>{&reference, "reference"}, {&source, "source"}}) {
    Status s = check_mesh(mesh->V, mesh->F);
    if (!s.ok()) {
      out.status = Status::error(s.code, std::string(name) + " mesh: " + s.message);
      return out;
    }
    if (mesh->num_vertices() <= 2 * kp) {
      out.status = Status::error(StatusCode::InvalidMesh,
                                 std::string(name) + " mesh has " + std::to_string(mesh->num_vertices()) +
                                     " vertices: too coarse for " + std::to_string(kp) +
                                     " eigenpairs (needs more than " + std::to_string(2 * kp) + "); subdivide it");
      return out;
    }
  }
  // Landmarks.
  const bool same_connectivity = reference.num_vertices() == source.num_vertices() && reference.F == source.F;
  out.landmarks = landmarks;
  if (out.landmarks.empty()) {
    if (!same_connectivity) {
      out.status = Status::error(StatusCode::InvalidArgument,
                                 "the meshes have different connectivity (" + std::to_string(reference.num_vertices()) +
                                     " and " + std::to_string(source.num_vertices()) +
                                     " vertices): pass landmark pairs (reference vertex, source vertex)");
      return out;
    }
    for (int v : farthest_point_landmarks(source.V, source.F, opt.landmarks.auto_count)) out.landmarks.push_back({v, v});
  }
  out.status = check_landmarks(out.landmarks, reference.num_vertices(), source.num_vertices(), opt.landmarks.min_landmarks);
  if (!out.status.ok()) return out;

  Normalized ref, src;
  if (!(out.status = normalize(reference, "reference", &ref)).ok()) return out;
  if (!(out.status = normalize(source, "source", &src)).ok()) return out;

  // 4–5. Cage and mean-value coordinates (Yin only). They depend on the source alone, so with
  // threads they run on a second thread while the eigenbases and the coupling are computed (the
  // results are the same either way; with max_threads() = 1, and in the single-threaded wasm
  // build, they run in sequence below).
  // Progress of the cage thread: recorded under a mutex (fractions kept monotone) and reported by
  // this thread alone — while it waits for the cage, it polls the record (in wasm the sink calls
  // JavaScript, which only this thread can reach).
  struct CageStage {
    Status status;
    Eigen::MatrixXd C, Cn, Psi;
    Eigen::MatrixXi CF;
    double ms_cage = 0, ms_mvc = 0;
  };
  auto cage_stage = [&source, &src, &opt, user_cage](const EnclosingCageOptions& cage_options, const Progress& cage_progress,
                                                     const Progress& mvc_progress) {
    CageStage r;
    auto t = clock::now();
    if (user_cage) {
      r.C = user_cage->V;
      r.CF = user_cage->F;
      r.status = check_user_cage(source.V, r.C, &r.CF, opt.cage.min_clearance * 1e-3);
      if (!r.status.ok()) return r;
    } else {
      EnclosingCage cage = enclosing_cage(source.V, source.F, cage_options, cage_progress);
      if (!cage.status.ok()) {
        r.status = cage.status;
        return r;
      }
      r.C = std::move(cage.V);
      r.CF = std::move(cage.F);
    }
    r.ms_cage = elapsed_ms(t);
    // Mean-value coordinates are similarity invariant: computed in normalized coordinates.
    t = clock::now();
    r.Cn = (r.C.rowwise() - src.centroid) / src.scale;
    // (Its rows are split across the task threads inside; the calling thread takes a block once
    // it only waits for the cage.)
    MeanValueCoordinates mvc = mean_value_coordinates(src.V, r.Cn, r.CF, mvc_progress);
    if (!mvc.status.ok()) {
      r.status = mvc.status;
      return r;
    }
    r.Psi = std::move(mvc.Psi);
    r.ms_mvc = elapsed_ms(t);
    return r;
  };
  // Declared before the task: its destructor waits for the thread, which uses these.
  struct CageReport {
    std::mutex mutex;
    bool recorded = false;
    std::string stage;
    double fraction = 0;
  } report;
  const Progress cage_range = progress.sub(0.4, 0.85);
  CageStage cage_result;
  // Declared after what it writes: whatever returns early below stops the cage task and waits for it.
  StoppableTask cage_task;
#if MM_HAS_THREADS
  if (opt.method == TransferMethod::Yin && max_threads() > 1) {
    const auto record = [&report](const std::string& stage, double f) {
      std::lock_guard<std::mutex> lock(report.mutex);
      report.stage = stage;
      report.fraction = std::max(f, report.fraction);
      report.recorded = true;
      return true;
    };
    cage_task = StoppableTask(
        [&cage_result, cage_stage, &opt](const Progress& watch) {
          cage_result = cage_stage(opt.cage, watch.sub(0.0, 0.45), watch.sub(0.45, 1.0));
        },
        record);
  }
#endif

  // 2. Eigenbases.
  auto t0 = clock::now();
  SpectralBasisOptions so;
  so.k = kp;
  const SpectralBasis basis_ref =
      spectral_basis(cotan_stiffness(ref.V, reference.F), ref.mass, so, progress.sub(0.0, 0.17));
  if (!basis_ref.status.ok()) {
    out.status = Status::error(basis_ref.status.code, "reference eigenbasis: " + basis_ref.status.message);
    return out;
  }
  const SpectralBasis basis_src =
      spectral_basis(cotan_stiffness(src.V, source.F), src.mass, so, progress.sub(0.17, 0.35));
  if (!basis_src.status.ok()) {
    out.status = Status::error(basis_src.status.code, "source eigenbasis: " + basis_src.status.message);
    return out;
  }
  out.ms.eigenbases = elapsed_ms(t0);

  // 3. Coupling.
  t0 = clock::now();
  const LandmarkFunctions lf = landmark_functions(reference.F, ref.mass, source.F, src.mass, out.landmarks, opt.landmarks);
  if (!lf.status.ok()) {
    out.status = lf.status;
    return out;
  }
  Eigen::MatrixXd Phi_src, Phi_ref;  // the bases whose first K+1 columns carry the pose
  if (opt.method == TransferMethod::Levy) {
    // Plain eigenbases; reference signs matched to the source through the landmark functions.
    Phi_src = basis_src.vectors;
    Phi_ref = basis_ref.vectors;
    const Eigen::MatrixXd Cs = Phi_src.transpose() * src.mass.asDiagonal() * lf.source;
    const Eigen::MatrixXd Cr = Phi_ref.transpose() * ref.mass.asDiagonal() * lf.reference;
    for (int i = 0; i < kp; ++i)
      if (Cs.row(i).dot(Cr.row(i)) < 0) Phi_ref.col(i) = -Phi_ref.col(i);
    const Eigen::MatrixXd Cr2 = Phi_ref.transpose() * ref.mass.asDiagonal() * lf.reference;
    const int k = opt.coupling.num_coupled;
    functional_matrix(Cs.topRows(k), Cr2.topRows(k), K + 1, &out.gamma, &out.gamma_dominance);
    out.coupling_converged = true;
  } else {
    CoupledBasesOptions co = opt.coupling;
    co.dominance_rows = K + 1;
    const CoupledBases cb = coupled_bases(basis_src.vectors, basis_src.eigenvalues, src.mass, lf.source,
                                          basis_ref.vectors, basis_ref.eigenvalues, ref.mass, lf.reference, co,
                                          progress.sub(0.35, 0.4));
    if (!cb.status.ok()) {
      out.status = cb.status;
      return out;
    }
    Phi_src = cb.source;
    Phi_ref = cb.reference;
    out.gamma = cb.gamma;
    out.gamma_dominance = cb.diagonal_dominance;
    out.coupling_iterations = cb.iterations;
    out.coupling_converged = cb.converged;
  }
  out.ms.coupling = elapsed_ms(t0);

  // Low-frequency coefficients (Eq. 3; A-weighted inner products of the A-orthonormal bases).
  const Eigen::MatrixXd PhiK_src = Phi_src.leftCols(K + 1);
  const Eigen::MatrixXd alpha_ref = Phi_ref.leftCols(K + 1).transpose() * ref.mass.asDiagonal() * ref.V;
  const Eigen::MatrixXd alpha_src = PhiK_src.transpose() * src.mass.asDiagonal() * src.V;

  Eigen::MatrixXd Vn;  // result in normalized coordinates
  if (opt.method != TransferMethod::Yin) {
    Vn = src.V + PhiK_src * (alpha_ref - alpha_src);  // Eq. 4
  } else {
    // Wait for the cage task, reporting its progress from here every 40 ms (and running a block
    // of the mean-value rows when one is queued).
    const bool cage_threaded = cage_task.valid();
    if (cage_threaded) {
      bool done = false;
      while (!done) {
        done = cage_task.wait_for(std::chrono::milliseconds(40));
        std::string stage;
        double fraction = 0;
        {
          std::lock_guard<std::mutex> lock(report.mutex);
          if (!report.recorded) continue;
          stage = report.stage;
          fraction = report.fraction;
        }
        if (!cage_task.stop_requested() && !cage_range.update(stage, fraction)) cage_task.request_stop();
      }
    }
    CageStage cs = cage_threaded ? std::move(cage_result)
                                 : cage_stage(opt.cage, progress.sub(0.4, 0.6), progress.sub(0.6, 0.85));
    if (!cs.status.ok()) {
      out.status = cs.status;
      return out;
    }
    if (!cage_range.update("mean-value coordinates", 1.0)) {
      out.status = cancelled_status("mean-value coordinates");
      return out;
    }
    // 6. Optimisation (Eq. 12, App. B) in the cage of `stage`; fills o's cage, solver and
    // position fields.
    const Eigen::RowVector3d place = opt.placement == TransferPlacement::Reference ? ref.centroid : src.centroid;
    auto optimise = [&](const CageStage& stage, const Progress& p, PoseTransferResult* o) -> Status {
      const auto t = clock::now();
      o->cage_rest = stage.C;
      o->cage_faces = stage.CF;
      o->ms.cage = stage.ms_cage;
      o->ms.mvc = stage.ms_mvc;
      CagePoseProblem prob;
      prob.C = stage.Cn;
      prob.CF = stage.CF;
      prob.P = PhiK_src.transpose() * src.mass.asDiagonal() * stage.Psi;  // Eq. 8: Φ̂_Kᵀ A Ψ
      prob.T = alpha_ref;
      o->fixed_cage_vertices = 0;
      if (opt.fixed_cage_weight > 0) {
        // The lightest cage vertices held, in normalized coordinates (where the optimisation runs).
        const Eigen::VectorXd w = stage.Psi.cwiseAbs().transpose() * src.mass;
        std::vector<int> order(static_cast<size_t>(w.size()));
        std::iota(order.begin(), order.end(), 0);
        std::stable_sort(order.begin(), order.end(), [&w](int x, int y) { return w[x] < w[y]; });
        const double budget = opt.fixed_cage_weight * w.sum();
        double held = 0;
        for (int c : order) {
          if ((held += w[c]) > budget) break;
          prob.fixed.push_back(c);
        }
        std::sort(prob.fixed.begin(), prob.fixed.end());
        prob.fixed_positions.resize(static_cast<Eigen::Index>(prob.fixed.size()), 3);
        for (size_t f = 0; f < prob.fixed.size(); ++f)
          prob.fixed_positions.row(static_cast<Eigen::Index>(f)) = stage.Cn.row(prob.fixed[f]);
        o->fixed_cage_vertices = static_cast<int>(prob.fixed.size());
      }
      const CagePoseResult sol = solve_cage_pose(prob, opt.solver, p);
      if (!sol.status.ok()) return sol.status;
      o->iterations = sol.iterations;
      o->converged = sol.converged;
      o->energy = sol.energy;
      o->energy_lf = sol.energy_lf;
      o->energy_lc = sol.energy_lc;
      o->energy_sf = sol.energy_sf;
      o->V = (src.scale * (stage.Psi * sol.C)).rowwise() + place;
      o->cage_deformed = (src.scale * sol.C).rowwise() + place;
      o->ms.optimisation = elapsed_ms(t);
      if (!o->V.allFinite()) return Status::error(StatusCode::NumericalError, "pose transfer produced non-finite positions");
      return Status{};
    };
    const bool retry_folds = opt.fold_retry_resolution > opt.cage.resolution;
    const bool check_folds = !user_cage && (retry_folds || opt.flip_repair_rings > 0);
    if (!(out.status = optimise(cs, progress.sub(0.85, check_folds ? 0.9 : 1.0), &out)).ok()) return out;
    if (check_folds) {
      // No folds at the whole-body step (PoseTransferOptions::fold_retry_resolution).
      out.fold_retry.checked = true;
      out.folds = fold_report(reference, source, out.V);
      if (retry_folds && out.folds.violations() > 0) {
        if (!progress.update("cage on a finer grid (the result folds)", 0.9)) {
          out.status = cancelled_status("cage on a finer grid");
          return out;
        }
        const auto t_retry = clock::now();
        out.fold_retry.tried = true;
        out.fold_retry.resolution = opt.fold_retry_resolution;
        out.fold_retry.first = out.folds;
        EnclosingCageOptions finer = opt.cage;
        finer.resolution = opt.fold_retry_resolution;
        const CageStage cs2 = cage_stage(finer, progress.sub(0.9, 0.95), progress.sub(0.95, 0.97));
        PoseTransferResult alt;
        Status s = cs2.status;
        if (s.ok()) s = optimise(cs2, progress.sub(0.97, 1.0), &alt);
        if (s.code == StatusCode::Cancelled) {
          out.status = s;
          return out;
        }
        if (s.ok()) {
          alt.folds = fold_report(out.folds, source, alt.V);
          if (alt.folds.violations() < out.folds.violations()) {
            out.fold_retry.kept = true;
            out.cage_rest = std::move(alt.cage_rest);
            out.cage_faces = std::move(alt.cage_faces);
            out.cage_deformed = std::move(alt.cage_deformed);
            out.fixed_cage_vertices = alt.fixed_cage_vertices;
            out.iterations = alt.iterations;
            out.converged = alt.converged;
            out.energy = std::move(alt.energy);
            out.energy_lf = alt.energy_lf;
            out.energy_lc = alt.energy_lc;
            out.energy_sf = alt.energy_sf;
            out.V = std::move(alt.V);
            out.folds = alt.folds;
          }
        }
        out.fold_retry.ms = elapsed_ms(t_retry);
      }
      if (!(out.status = repair_transfer_flips(source, opt.flip_repair_rings, progress.sub(0.99, 1.0), &out.V,
                                               &out.folds, &out.flip_repair)).ok())
        return out;
    }
  }
  if (opt.method != TransferMethod::Yin) {
    const Eigen::RowVector3d place = opt.placement == TransferPlacement::Reference ? ref.centroid : src.centroid;
    out.V = (src.scale * Vn).rowwise() + place;
  }
  if (!out.V.allFinite()) {
    out.status = Status::error(StatusCode::NumericalError, "pose transfer produced non-finite positions");
    return out;
  }
  out.ms.total = elapsed_ms(t_start);
  progress.update("done", 1.0);
  return out;
}

}  // namespace mm
