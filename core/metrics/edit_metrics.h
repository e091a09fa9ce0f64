// Quality measures for mesh editing (paper 001): local rigidity, shear of deformation gradients,
// edge-length distortion, detail preservation, inverted triangles. Used by tests, bench and CLI.
//
// All functions take the rest positions V0 and deformed positions V1 (#V by 3, same
// connectivity F, #F by 3; conventions in mesh/mesh.h) and never fail: vertices or faces where a
// measure is undefined (isolated vertex, zero-length ring) get 0.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace mm {

// Per-vertex local rigidity error: the best similarity (rotation, uniform scale, translation;
// Umeyama) mapping the rest closed 1-ring {i} ∪ N(i) onto the deformed one; the RMS residual
// divided by the RMS distance of the deformed ring points to their centroid. 0 = the ring moved by
// a similarity; dimensionless. Returns #V values.
Eigen::VectorXd local_rigidity_error(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F);

// Deformation gradients of a result: per vertex the least-squares linear map of the rest 1-ring
// onto the deformed one (paper 001 Eq. 4), with the vertex normals (scaled by the mean ring edge
// length) as an extra column so that planar rings are well defined. #V by 9 (row-major 3x3).
Eigen::MatrixXd fitted_gradients(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F);

// Shear of a deformation gradient M = R S (polar): ||S − s I||_F / (√3 · s) with
// s = sqrt(mean squared singular value). 0 for rotation × uniform scale. G: #V by 9 (row-major).
double gradient_shear(const Eigen::Matrix3d& M);
Eigen::VectorXd gradient_shear(const Eigen::MatrixXd& G);

struct EdgeDistortion {
  double mean = 0;  // mean over edges of |l1 − l0| / l0
  double max = 0;   // largest such value
};
EdgeDistortion edge_length_distortion(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F);

// Per-vertex angle in degrees (0..90) between the line of the deformed Laplacian coordinate
// D(ṽ_i) = Σ_j w_ij (ṽ_j − ṽ_i) — cotangent weights w_ij of the REST mesh V0, as in paper 001
// Eq. 1, applied to the deformed positions V1 — and the line of the vertex normal of V1. Rest
// weights matter: the deformed mesh's own cotangent Laplacian is parallel to its normal for any
// smooth surface and would not show whether details were rotated. #V values.
Eigen::VectorXd laplacian_normal_angle(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F);

struct DetailPreservation {
  double mean_angle_deg = 0;       // |δ0|-weighted mean of laplacian_normal_angle(V0, V1) over `vertices`
  double rest_mean_angle_deg = 0;  // the same measure at rest, (V0, V0): the mesh's discretisation floor
};
// Detail preservation over a vertex subset (all vertices when empty). Weights are the rest
// Laplacian-coordinate magnitudes |(W V0)_i|, so that flat areas (whose LC direction is noise)
// do not dominate.
DetailPreservation detail_preservation(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F,
                                       const std::vector<int>& vertices = {});

// Faces whose orientation flipped: the deformed normal opposes the rest normal carried by the
// best-fit rotation of the face's vertices and their 1-rings (so large rigid rotations of a region
// are not counted). Returns the face indices, ascending.
std::vector<int> inverted_faces(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F);

// Mean of v over `subset` (all entries when empty).
double mean_over(const Eigen::VectorXd& v, const std::vector<int>& subset = {});

}  // namespace mm
