#include "edit/laplacian_editor_impl.h"

#include "linalg/iterative_refinement.h"

namespace mm {

using namespace edit_detail;

// Handle response basis (this implementation's precomputation, not in paper 001). Stage 1 solves
// for displacements from the displaced rest mesh, and a handle moved by x ↦ A_h x + t_h displaces
// its vertices by (A_h − I)(v' − c_h) + τ_h with τ_h = (A_h − I) c_h + t_h (c_h the handle's rest
// centroid, so that the basis columns stay of the handle's size wherever the mesh sits). The
// solution is linear in these: u_U = Σ_h Φ_h [(A_h − I) τ_h]ᵀ, Φ_h (4 columns) per handle, each
// column one Eq. 7 solve with the stage 1 factor (fixed vertices do not move: no Φ_0). The
// columns are refined against the unsquared system here (they are exact solutions of linear
// least-squares problems like any drag), so drag() gets refined results for the price of a
// dense product.
Status LaplacianEditor::Impl::build_handle_basis(EditBuild& s, const Progress& progress) {
  auto& clock = s.clock;
  const int m = 4 * num_handles;
  // Centroids of the constrained handle vertices (hard: known; soft: unknowns with a soft row).
  handle_center.assign(num_handles, Eigen::Vector3d::Zero());
  std::vector<int> count(num_handles, 0);
  auto constrained = [&](int l) { return group[l] >= 0 && (l >= nU || soft[l] > 0); };
  for (int l = 0; l < nL; ++l)
    if (constrained(l)) {
      handle_center[group[l]] += Vd.row(l2g[l]).transpose();
      ++count[group[l]];
    }
  for (int h = 0; h < num_handles; ++h)
    if (count[h] > 0) handle_center[h] /= count[h];
  // Unit responses: column 4h + c moves handle h's vertices by their offset c from c_h (and
  // pulls its gradients towards e_c), column 4h + 3 translates them by 1.
  Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(nL, m), soft_target;
  if (opt.soft_constraint_weight > 0) soft_target = Eigen::MatrixXd::Zero(nU, m);
  for (int l = 0; l < nL; ++l) {
    if (!constrained(l)) continue;
    const int g = group[l];
    Eigen::MatrixXd& dst = l >= nU ? Y : soft_target;
    dst.block(l, 4 * g, 1, 3) = Vd.row(l2g[l]) - handle_center[g].transpose();
    dst(l, 4 * g + 3) = 1.0;
  }
  std::vector<Eigen::MatrixXd> grad_rhs;
  if (opt.gradient_constraint_weight > 0)
    for (int h = 0; h < num_handles; ++h) {
      grad_rhs.push_back(Eigen::MatrixXd::Zero(3, m));
      grad_rhs.back().block(0, 4 * h, 3, 3).setIdentity();
    }
  if (!progress.update("edit: handle basis", 0.9)) return cancelled_status("edit: handle basis");
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(nU, m);
  bool from_zero = true;  // refine_solution starts from X = 0
  const IterativeRefinementReport rep = refine_solution(
      [&](const Eigen::MatrixXd& xx, Eigen::MatrixXd* g) {
        Y.topRows(nU) = xx;
        stage1_normal_residual(Y, grad_rhs, soft_target, g, from_zero);
        from_zero = false;
      },
      [&](Eigen::MatrixXd* r) { solver1.solve_in_place(*r); }, &X, opt.residual_refinements);
  if (!rep.status.ok()) return rep.status;
  stats.basis_refinements = rep.steps;
  Phi.resize(num_handles);
  for (int hh = 0; hh < num_handles; ++hh) Phi[hh] = X.middleCols(4 * hh, 4);
  have_basis = true;
  stats.basis_ms = edit_lap_ms(&clock);
  return Status::success();
}

}  // namespace mm
