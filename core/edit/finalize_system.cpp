#include "edit/laplacian_editor_impl.h"

#include <chrono>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "edit/shear_removal.h"
#include "linalg/iterative_refinement.h"

namespace mm {

using namespace edit_detail;

// Stage 2 (paper 001 Sec. 4): the Poisson system D ṽ = T δ on the undisplaced mesh, with
// T_i = R_i (Eq. 9) or R_i S_i (Eq. 10). Built once: W_UU, W_UK (hard constraints eliminated) or
// the row-scaled least-squares system (soft constraints), and the rest Laplacian coordinates.
Status LaplacianEditor::Impl::build_finalize_system(EditBuild& s, const Progress& progress) {
  const bool soft_mode = s.soft_mode, cot = s.cot;
  const double h = s.h;
  // Its own clock: natively this stage may run beside the Eq. 7 system (laplacian_editor.cpp).
  auto clock = std::chrono::steady_clock::now();
  // Stage 2 operator (undisplaced mesh): W_UU, W_UK and rest Laplacian coordinates.
  EditSparse W2;
  Eigen::VectorXd ds2;
  laplacian_rows(s, V, &W2, &ds2);
  Eigen::MatrixXd Xrest(nL, 3);
  for (int l = 0; l < nL; ++l) Xrest.row(l) = V.row(l2g[l]);
  LC = W2 * Xrest;
  const edit_detail::RowSparse rows = W2;
  edge_begin.assign(1, 0);
  for (int l = 0; l < nU; ++l) {
    for (edit_detail::RowSparse::InnerIterator it(rows, l); it; ++it) {
      const int j = static_cast<int>(it.col());
      if (j == l || it.value() == 0) continue;
      edge_end_vertex.push_back(j);
      edge_weight.push_back(-it.value());  // W is PSD: off-diagonal −w_ij
      edge_rest.emplace_back((Xrest.row(l) - Xrest.row(j)).transpose());
    }
    edge_begin.push_back(static_cast<int>(edge_end_vertex.size()));
  }
  if (!soft_mode) {
    D2_UU = W2.leftCols(nU);
    D2_UK = W2.rightCols(nL - nU);
  } else {
    // Rows scaled to the paper's D (dimensionless with h): the least-squares weights matter here.
    row_scale2 = (cot ? h : 1.0 / h) * ds2;
    for (int l = 0; l < nU; ++l)
      if (!has_row[l]) row_scale2[l] = 0;
    const EditSparse Ds = row_scale2.asDiagonal() * W2;
    D2_UU = Ds.leftCols(nU);
    D2_UK = Ds.rightCols(nL - nU);
  }
  if (!progress.update("edit: poisson factor", 0.06)) return cancelled_status("edit: poisson factor");
  EditSparse N2;
  if (!soft_mode) {
    N2 = D2_UU;
  } else {
    N2 = EditSparse(D2_UU.transpose()) * D2_UU;
    for (int l = 0; l < nU; ++l)
      if (soft[l] > 0) N2.coeffRef(l, l) += soft[l];
  }
  if (Status s = solver2.factor(N2); !s.ok())
    return Status::error(s.code, "Poisson system (Eq. 9/10): " + s.message);
  stats.poisson_ms = edit_lap_ms(&clock);
  return Status::success();
}

// Solved for displacements u = x − v from the rest mesh: D v = δ, so D u = T δ − δ, whose right-hand
// side vanishes exactly where T = I (the identity edit returns the input bit for bit).
// Soft constraints: the normal equations DᵀD + soft square the condition number, and every solve
// is refined against the unsquared rows (measured on a 28.8k-vertex cat, similarity on all
// constraints, soft weight 10: 1.3e-4 of the diagonal → 2e-13). Hard constraints: D_UU itself
// is factored, a backward-stable solve of a square SPD system; refinement in working precision
// cannot improve its forward error and measured no change (1.9e-13 either way), so it is skipped
// there — one solve per finalize pass, as before.
EditResult LaplacianEditor::Impl::solve_stage2(bool use_rotations, FeatureSize mode) {
  EditResult out;
  const int nK = nL - nU;
  Eigen::MatrixXd known_u(nK, 3);
  for (int k = 0; k < nK; ++k) known_u.row(k) = known.row(k) - V.row(l2g[nU + k]);
  const bool soft_mode = opt.soft_constraint_weight > 0;
  Eigen::MatrixXd soft_uo;
  if (soft_mode) {
    soft_uo = Eigen::MatrixXd::Zero(nU, 3);
    for (int l = 0; l < nU; ++l)
      if (soft[l] > 0) soft_uo.row(l) = soft_u.row(l) - V.row(l2g[l]);
  }
  const Eigen::MatrixXd known_rhs = D2_UK * known_u;
  Eigen::MatrixXd b(nU, 3), x;
  int refinements = 0;
  // b is the change of the right-hand side, T δ − δ.
  const int refine_steps = soft_mode ? opt.residual_refinements : 0;
  auto solve2 = [&](const Eigen::MatrixXd& bb, Eigen::MatrixXd* xx) {
    Eigen::MatrixXd scaled_b;
    if (soft_mode) scaled_b = row_scale2.asDiagonal() * bb;
    *xx = Eigen::MatrixXd::Zero(nU, 3);
    const IterativeRefinementReport rep = refine_solution(
        [&](const Eigen::MatrixXd& u, Eigen::MatrixXd* g) {
          if (soft_mode) {
            *g = D2_UU.transpose() * (scaled_b - D2_UU * u - known_rhs);
            for (int l = 0; l < nU; ++l)
              if (soft[l] > 0) g->row(l) += soft[l] * (soft_uo.row(l) - u.row(l));
          } else {
            *g = bb - D2_UU * u - known_rhs;
          }
        },
        [&](Eigen::MatrixXd* r) { solver2.solve_in_place(*r); }, xx, refine_steps);
    refinements += rep.steps;
    return rep.status;
  };
  // The same equation with δ_i = Σ_j w_ij (v_i − v_j) rotated edge by edge:
  // b_i = Σ_j w_ij s_ij R_ij (v_i − v_j) with R_ij the geodesic midpoint of R_i and R_j and s_ij
  // the mean scale. Equal to T_i δ_i where T is constant; where it varies, the difference carries
  // the bend of thin parts.
  auto per_edge_rhs = [&](const std::vector<Eigen::Matrix3d>& T, const std::vector<double>& S, Eigen::MatrixXd* bb) {
    std::vector<Eigen::Quaterniond> q(T.size());
    for (size_t l = 0; l < T.size(); ++l) q[l] = Eigen::Quaterniond(T[l]);
    for (int l = 0; l < nU; ++l) {
      Eigen::Vector3d acc = Eigen::Vector3d::Zero();
      for (int e = edge_begin[l]; e < edge_begin[l + 1]; ++e) {
        const int j = edge_end_vertex[e];
        // Geodesic midpoint of the two rotations: the normalized sum of their quaternions (same
        // hemisphere).
        const Eigen::Quaterniond qj = q[l].dot(q[j]) < 0 ? Eigen::Quaterniond(-q[j].coeffs()) : q[j];
        const Eigen::Quaterniond qm = Eigen::Quaterniond(q[l].coeffs() + qj.coeffs()).normalized();
        acc.noalias() += edge_weight[e] * (0.5 * (S[l] + S[j]) * (qm * edge_rest[e]) - edge_rest[e]);
      }
      bb->row(l) = acc.transpose();
    }
  };
  const bool per_edge = use_rotations && opt.rotated_coordinates == RotatedCoordinates::PerEdge;
  std::vector<Eigen::Matrix3d> T;
  std::vector<double> S;
  if (use_rotations) {
    // Sec. 4: M_i = U W Vᵀ → R_i = U Vᵀ, s_i = sqrt((λ1² + λ2² + λ3²)/3); T_i = R_i (Eq. 9) or
    // R_i S_i (Eq. 10). Constrained vertices (hard or soft) take their handle's similarity, fixed
    // ones the identity (one polar decomposition per handle, not per vertex).
    auto scale_of = [&](const Eigen::Matrix3d& M) {
      return mode == FeatureSize::Scale ? std::sqrt(M.squaredNorm() / 3.0) : 1.0;  // Σσ² = ||M||²_F
    };
    std::vector<Eigen::Matrix3d> handle_R(num_handles);
    std::vector<double> handle_s(num_handles);
    for (int h = 0; h < num_handles; ++h) {
      handle_R[h] = rotation_part(linear[h]);
      handle_s[h] = scale_of(linear[h]);
    }
    T.resize(per_edge ? nL : nU);
    S.resize(T.size());
    for (int l = 0; l < static_cast<int>(T.size()); ++l) {
      const int g = group[l];
      if (g == -2 && center_of[l] >= 0) {  // free unknown
        const Eigen::Matrix3d M = gradient_local(l);
        T[l] = rotation_part(M);
        S[l] = scale_of(M);
      } else if (g >= 0) {
        T[l] = handle_R[g];
        S[l] = handle_s[g];
      } else {
        T[l] = Eigen::Matrix3d::Identity();
        S[l] = 1.0;
      }
    }
    if (per_edge) {
      per_edge_rhs(T, S, &b);
    } else {
      // Eq. 9/10 literally: b_i = T_i δ_i with δ_i = (W v)_i (the row factor of D cancels).
      for (int l = 0; l < nU; ++l)
        b.row(l) = (S[l] * (T[l] * LC.row(l).transpose()) - LC.row(l).transpose()).transpose();
    }
  } else {
    b.setZero();  // naive Laplacian editing: unrotated Laplacian coordinates, D u = 0
  }
  Status st = solve2(b, &x);
  // Optional local/global refinement (not in the paper, PerEdge only): re-fit each free vertex's
  // rotation to its finalized 1-ring (cotangent-weighted, rest edges → deformed edges), solve again.
  for (int it = 0; per_edge && it < opt.finalize_refinements && st.ok(); ++it) {
    for (int l = 0; l < nU; ++l) {
      if (group[l] != -2) continue;
      Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
      const Eigen::Vector3d ul = x.row(l).transpose();
      for (int e = edge_begin[l]; e < edge_begin[l + 1]; ++e) {
        const int j = edge_end_vertex[e];
        const Eigen::Vector3d uj = j < nU ? Eigen::Vector3d(x.row(j).transpose()) : Eigen::Vector3d(known_u.row(j - nU).transpose());
        // Deformed edge x_l − x_j = (v_l − v_j) + (u_l − u_j).
        A.noalias() += std::abs(edge_weight[e]) * (edge_rest[e] + (ul - uj)) * edge_rest[e].transpose();
      }
      T[l] = rotation_part(A);
    }
    per_edge_rhs(T, S, &b);
    st = solve2(b, &x);
  }
  if (!st.ok()) {
    out.status = st;
    return out;
  }
  out.refinements = refinements;
  out.V = V;
  for (int l = 0; l < nU; ++l) out.V.row(l2g[l]) += x.row(l);
  for (int k = 0; k < nK; ++k) out.V.row(l2g[nU + k]) = known.row(k);
  if (!out.V.allFinite())
    out.status = Status::error(StatusCode::NumericalError, "the Poisson solve produced non-finite positions");
  return out;
}

}  // namespace mm
