#include "edit/laplacian_editor_impl.h"

namespace mm {

using namespace edit_detail;

// Handle response basis (this implementation's precomputation, not in paper 001): with the
// handles' similarities A_h, t_h the stage 1 solution of Eq. 7 is linear in them,
// x_U = Φ_0 + Σ_h Φ_h [A_h t_h]ᵀ, so a drag is a few dense products instead of back-substitutions. Φ_0 for the fixed part, Φ_h
// (4 columns) per handle, each one solve with the stage 1 factor.
Status LaplacianEditor::Impl::build_handle_basis(EditBuild& s, const Progress& progress) {
  auto& clock = s.clock;
  const int nK = nL - nU;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(nU, 3 + 4 * num_handles);
  Eigen::MatrixXd XK = Eigen::MatrixXd::Zero(nK, 3 + 4 * num_handles);
  for (int k = 0; k < nK; ++k) {
    const int l = nU + k, g = group[l];
    const Eigen::RowVector3d p = Vd.row(l2g[l]);
    if (g < 0) {
      XK.block(k, 0, 1, 3) = p;
    } else {
      XK.block(k, 3 + 4 * g, 1, 3) = p;
      XK(k, 3 + 4 * g + 3) = 1.0;
    }
  }
  R = -(Q1 * XK);
  for (int l = 0; l < nU; ++l) {
    if (!(soft[l] > 0)) continue;
    const int g = group[l];
    const Eigen::RowVector3d p = Vd.row(l2g[l]);
    if (g < 0) {
      R.block(l, 0, 1, 3) += soft[l] * p;
    } else {
      R.block(l, 3 + 4 * g, 1, 3) += soft[l] * p;
      R(l, 3 + 4 * g + 3) += soft[l];
    }
  }
  for (int hh = 0; hh < num_handles; ++hh) R.block(0, 3 + 4 * hh, nU, 3) += G1.block(0, 3 * hh, nU, 3);
  if (!progress.update("edit: handle basis", 0.9)) return cancelled_status("edit: handle basis");
  Eigen::MatrixXd X;
  if (Status s = solver1.solve(R, &X); !s.ok()) return s;
  Phi0 = X.leftCols(3);
  Phi.resize(num_handles);
  for (int hh = 0; hh < num_handles; ++hh) Phi[hh] = X.block(0, 3 + 4 * hh, nU, 4);
  have_basis = true;
  stats.basis_ms = edit_lap_ms(&clock);
  return Status::success();
}

}  // namespace mm
