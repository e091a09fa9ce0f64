#include "common/colormap.h"

#include <algorithm>
#include <cmath>

namespace mm {

Eigen::MatrixXd diverging_colors(const Eigen::VectorXd& f) {
  const double m = f.size() ? f.cwiseAbs().maxCoeff() : 0.0;
  Eigen::MatrixXd C(f.size(), 3);
  // Endpoints: blue (0.23, 0.30, 0.75) and red (0.71, 0.02, 0.15) from Moreland's cool-warm
  // map, white in the middle; linear in between is enough for a viewer.
  const Eigen::RowVector3d blue(0.23, 0.30, 0.75), white(0.97, 0.97, 0.97), red(0.71, 0.02, 0.15);
  for (int i = 0; i < f.size(); ++i) {
    const double t = (m > 0 && std::isfinite(f[i])) ? std::clamp(f[i] / m, -1.0, 1.0) : 0.0;
    C.row(i) = t < 0 ? white + (-t) * (blue - white) : white + t * (red - white);
  }
  return C;
}

}  // namespace mm
