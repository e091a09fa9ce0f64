#include "character/skinning.h"

namespace mm {

Eigen::MatrixXd linear_blend_skinning(const Eigen::MatrixXd& V, const SkinWeights& W, const Matrix4dList& M) {
  Eigen::MatrixXd out(V.rows(), 3);
  for (int i = 0; i < V.rows(); ++i) {
    Eigen::Matrix<double, 3, 4> B = Eigen::Matrix<double, 3, 4>::Zero();
    for (int k = 0; k < W.index.cols(); ++k) {
      const double w = W.weight(i, k);
      if (w == 0) continue;
      B += w * M[W.index(i, k)].topRows<3>();
    }
    out.row(i) = (B.leftCols<3>() * V.row(i).transpose() + B.col(3)).transpose();
  }
  return out;
}

}  // namespace mm
