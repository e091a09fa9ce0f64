// Analytic meshes for tests: exact geometry with known Laplace–Beltrami spectra.
#pragma once

#include <Eigen/Core>

namespace mm::test {

// Unit sphere by subdividing an icosahedron `level` times (projecting onto the sphere):
// level 5 gives 10,242 vertices / 20,480 faces. Outward (CCW) orientation.
void icosphere(int level, Eigen::MatrixXd* V, Eigen::MatrixXi* F);

// Regular grid of nx × ny vertices on [0,1]² (z = 0), two triangles per cell, CCW from +z.
void grid(int nx, int ny, Eigen::MatrixXd* V, Eigen::MatrixXi* F);

}  // namespace mm::test
