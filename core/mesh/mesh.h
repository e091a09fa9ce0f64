// Mesh: the triangle mesh every algorithm works on.
//
// Conventions (owned here, other headers point to this one):
// - V is #V by 3 (double), F is #F by 3 (int, 0-based) vertex indices.
// - Triangles are counter-clockwise seen from outside: the face normal is
//   (V[F(f,1)] - V[F(f,0)]) x (V[F(f,2)] - V[F(f,0)]), pointing out of a closed surface.
// - A Mesh carries no attributes; UVs, normals, materials stay in io::Asset.
#pragma once

#include <Eigen/Core>

namespace mm {

struct Mesh {
  Eigen::MatrixXd V;  // #V by 3 positions
  Eigen::MatrixXi F;  // #F by 3 triangle vertex indices

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }
};

// Length of the bounding-box diagonal of V (0 for an empty V). The unit of every
// "relative to the bounding-box diagonal" tolerance in tests and metrics.
double bounding_box_diagonal(const Eigen::MatrixXd& V);

}  // namespace mm
