#include "io/grouped_normals.h"

#include <Eigen/Geometry>

namespace mm::io {

Eigen::MatrixXd grouped_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                const Eigen::MatrixXi& G, int num_groups) {
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(num_groups, 3);
  const int nv = static_cast<int>(V.rows());
  for (int f = 0; f < F.rows(); ++f) {
    bool ok = true;
    for (int c = 0; c < 3; ++c) ok = ok && F(f, c) >= 0 && F(f, c) < nv;
    if (!ok) continue;
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    // The unnormalized cross product is twice the area times the unit normal: area weighting.
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!n.allFinite()) continue;
    for (int k = 0; k < 3; ++k) {
      const int g = G(f, k);
      if (g >= 0 && g < num_groups) N.row(g) += n.transpose();
    }
  }
  for (int g = 0; g < num_groups; ++g) {
    const double len = N.row(g).norm();
    if (len > 0) N.row(g) /= len;
  }
  return N;
}

}  // namespace mm::io
