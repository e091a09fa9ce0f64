#include "retarget/lbs_baseline.h"

#include <algorithm>
#include <map>

#include "linalg/rigid_fit.h"
#include "mesh/mesh.h"
#include "spatial/triangle_bvh.h"

namespace mm {

Eigen::Matrix4d Similarity::matrix() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = s * R;
  T.topRightCorner<3, 1>() = t;
  return T;
}

Eigen::MatrixXd Similarity::apply(const Eigen::MatrixXd& X) const {
  Eigen::MatrixXd Y = (X * R.transpose()) * s;
  Y.rowwise() += t.transpose();
  return Y;
}

Similarity align_rest_poses(const JointSet& source, const JointSet& target, const std::vector<JointPair>& pairs,
                            const Eigen::MatrixXd& V_source, const Eigen::MatrixXd& V_target) {
  Similarity A;
  const int n = static_cast<int>(pairs.size());
  if (n >= 3) {
    Eigen::MatrixXd S(n, 3), T(n, 3);
    for (int i = 0; i < n; ++i) {
      S.row(i) = source.P.row(pairs[i].source);
      T.row(i) = target.P.row(pairs[i].target);
    }
    // Target joints onto source joints: rotation snapped to the 24 axis-aligned ones (as
    // harmonic_retarget), scale and translation least-squares for that rotation.
    RigidFitOptions o;
    o.scale = o.snap_to_axes = true;
    o.min_spread = 1e-6;
    const RigidFit fit = fit_rigid(T, S, o);
    A.R = fit.R;
    A.s = fit.s;
    A.t = fit.t;
    if (!(A.s > 0)) {
      A.s = bounding_box_diagonal(V_source) / std::max(1e-300, bounding_box_diagonal(V_target));
      A.t = (S.colwise().mean() - A.s * T.colwise().mean() * A.R.transpose()).transpose();
    }
    return A;
  }
  A.s = bounding_box_diagonal(V_source) / std::max(1e-300, bounding_box_diagonal(V_target));
  const Eigen::RowVector3d cs = V_source.colwise().mean(), ct = V_target.colwise().mean();
  A.t = (cs - A.s * ct).transpose();
  return A;
}

SkinTransferResult transfer_skin_weights(const Eigen::MatrixXd& V_source, const Eigen::MatrixXi& F_source,
                                         const SkinWeights& sw, const Eigen::MatrixXd& Vt, int K) {
  SkinTransferResult r;
  if (V_source.rows() == 0 || F_source.rows() == 0) {
    r.status = Status::error(StatusCode::InvalidMesh, "skin weight transfer: the source surface is empty");
    return r;
  }
  const TriangleBvh bvh(V_source, F_source);
  r.weights.index = Eigen::MatrixXi::Zero(Vt.rows(), K);
  r.weights.weight = Eigen::MatrixXd::Zero(Vt.rows(), K);
  for (int i = 0; i < Vt.rows(); ++i) {
    const ClosestPoint cp = bvh.closest_point(Vt.row(i).transpose());
    std::map<int, double> acc;  // ordered: deterministic ties
    for (int c = 0; c < 3; ++c) {
      const int v = F_source(cp.face, c);
      for (int k = 0; k < sw.index.cols(); ++k)
        if (sw.weight(v, k) != 0) acc[sw.index(v, k)] += cp.barycentric[c] * sw.weight(v, k);
    }
    std::vector<std::pair<double, int>> sorted;
    for (const auto& [j, w] : acc) sorted.push_back({-w, j});
    std::stable_sort(sorted.begin(), sorted.end());
    double total = 0;
    for (int k = 0; k < K && k < static_cast<int>(sorted.size()); ++k) total += -sorted[k].first;
    for (int k = 0; k < K && k < static_cast<int>(sorted.size()); ++k) {
      r.weights.index(i, k) = sorted[k].second;
      r.weights.weight(i, k) = total > 0 ? -sorted[k].first / total : 0;
    }
  }
  return r;
}

Eigen::MatrixXd lbs_retarget(const Eigen::MatrixXd& V_target, const Similarity& A, const SkinWeights& W,
                             const Matrix4dList& M_source) {
  const Eigen::MatrixXd posed = linear_blend_skinning(A.apply(V_target), W, M_source);
  // Inverse similarity: x_t = Rᵀ (x_s − t) / s.
  return ((posed.rowwise() - A.t.transpose()) * A.R) / A.s;
}

}  // namespace mm
