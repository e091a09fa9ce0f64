// nonrigid_icp: optimal-step non-rigid ICP (Amberg, Romdhani, Vetter, CVPR 2007), used by
// paper 002 Sec. 6 (which cites Li et al. 2008) to find the target nodes compatible with the
// source's Context Graph. Experimental.
//
// A template graph (points P, edges) deforms onto a target surface with one affine map per
// template point, X_i (4 by 3, x_i' = [p_iᵀ 1] X_i). For each stiffness α of a decreasing
// schedule, repeatedly: closest target points u_i of the current x_i', then the sparse linear
// least-squares problem
//     α² ‖(M ⊗ G) X‖²  +  Σ_i w_i ‖[p_iᵀ 1] X_i − u_i‖²  +  β² Σ_l ‖[s_lᵀ 1] X_{k_l} − t_l‖²
// (M: node–arc incidence of the edges, G = diag(1, 1, 1, γ); w_i = 0 for correspondences
// farther than max_distance; landmarks: the affine map of template point k_l applied to the
// point s_l, e.g. a joint inside the surface near k_l, should give t_l), solved through its normal
// equations with a sparse Cholesky factorization (Eigen SimplicialLDLT), until X changes less
// than `tolerance`. β decreases with α (landmarks guide the coarse steps, the data the fine).
//
// Conventions: all points in one frame; distances relative to the target's bbox diagonal.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "spatial/triangle_bvh.h"

namespace mm {

struct NonrigidIcpOptions {
  std::vector<double> stiffness{100, 50, 20, 10, 5, 2, 1};  // α schedule, decreasing
  int max_inner_iterations = 5;  // solves per stiffness step at most
  double tolerance = 1e-4;       // stop a step when max |ΔX| < tolerance
  double gamma = 1;              // G = diag(1, 1, 1, γ): weight of the translation part in the stiffness
  double landmark_weight = 1;    // β at the first step, × sqrt(#P / #landmarks); then ∝ (α/α₀)^landmark_decay
  double landmark_decay = 0;     // 0 = landmarks keep their weight (measured: 1, Amberg's
                                 // annealing, lets surface points slide along the limbs at the
                                 // soft steps — CesiumMan 0.927 → 0.896 of nodes within 2%)
  double max_distance = 0.1;     // correspondences farther than this × target diagonal get w = 0
  double converged_residual = 0.01;  // converged when the mean distance of the deformed template to
                                     // the target is below this × target diagonal ...
  double converged_valid = 0.9;      // ... and at least this fraction of correspondences is valid
};

struct NonrigidIcpResult {
  Status status;               // FactorizationFailed / NumericalError; NotConverged is not an error
                               // here: see `converged`
  Eigen::MatrixXd X;           // #P by 3 deformed template points
  Eigen::MatrixXd closest;     // #P by 3 closest target points of X (the correspondences)
  bool converged = false;      // residual and valid fraction met (see options)
  double mean_residual = 0;    // mean |X − closest| / target diagonal at the end
  double valid_fraction = 0;   // correspondences within max_distance at the end
  int solves = 0;              // linear solves performed
};

// P: #P by 3 template points; edges: pairs of rows of P (the stiffness graph; components may be
// disconnected). target: the target surface. landmark_vertex (#L), landmark_point (#L by 3, in
// the template's frame), landmark_target (#L by 3): see the header comment; may be empty.
NonrigidIcpResult nonrigid_icp(const Eigen::MatrixXd& P, const std::vector<std::pair<int, int>>& edges,
                               const TriangleBvh& target, const Eigen::VectorXi& landmark_vertex,
                               const Eigen::MatrixXd& landmark_point, const Eigen::MatrixXd& landmark_target,
                               const NonrigidIcpOptions& opt = {});

// Symmetric k-nearest-neighbour edges (i < j, sorted) over the rows of P: a stiffness graph for
// point templates (brute force, O(#P²); meant for a few thousand points).
std::vector<std::pair<int, int>> knn_edges(const Eigen::MatrixXd& P, int k);

// Unique edges (i < j, sorted) of a triangle list.
std::vector<std::pair<int, int>> triangle_edges(const Eigen::MatrixXi& F);

}  // namespace mm
