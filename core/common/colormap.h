// Colour maps for showing scalar functions on meshes (eigenfunctions, error maps) as vertex
// colours. Pure functions, no state.
#pragma once

#include <Eigen/Core>

namespace mm {

// Diverging blue–white–red map of f, symmetric about 0: the largest |f| maps to full blue
// (negative) or red (positive). Returns #f by 3 RGB in [0, 1]. f all zero gives white.
Eigen::MatrixXd diverging_colors(const Eigen::VectorXd& f);

}  // namespace mm
