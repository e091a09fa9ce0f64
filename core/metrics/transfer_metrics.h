// Quality measures of a pose-transfer result (used by tests, bench and `meshmorph compare`).
//
// A (#V by 3) is compared with B (#V by 3, same vertex order), both over faces F:
// - vertex error (PMD): e_i = |a_i − b_i| / D, D = bounding-box diagonal of B;
//   reported as mean_i e_i and max_i e_i. Use B = ground truth.
// - Laplacian-coordinate magnitude change (detail preservation): with the uniform (umbrella)
//   Laplacian δ_i = x_i − mean of x's neighbours, which is rotation invariant in magnitude,
//   mean_i | |δ_i(A)| − |δ_i(B)| | / mean_i |δ_i(B)|. Use B = the source.
// - edge-length distortion: | |e(A)| / |e(B)| − 1 | over undirected edges, mean and max.
// - flipped faces: faces whose normal disagrees (negative dot product) with the area-weighted
//   mean normal of their edge-neighbouring faces in A but clearly agrees (dot > 0.5) in B —
//   local fold-overs (slivers with ambiguous normals in B are not counted),
//   independent of the global rotation of a pose.
// - collapsed faces: faces whose area in A, relative to the whole surface's, is below 1e-3 of
//   their relative area in B (a patch crushed to a sliver sheet; its normals are noise, so a
//   file written in single precision shows them as flips); those not also flipped are counted.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct TransferMetrics {
  Status status;                    // InvalidArgument when A and B differ in size
  double vertex_error_mean = 0;     // see header (bbox-diagonal units)
  double vertex_error_max = 0;
  double laplacian_change = 0;      // relative mean change of |δ|
  double edge_distortion_mean = 0;  // relative
  double edge_distortion_max = 0;
  int flipped_faces = 0;
  int collapsed_faces = 0;
  int faulty_faces() const { return flipped_faces + collapsed_faces; }  // what the flip repair removes
};

TransferMetrics transfer_metrics(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXi& F);

// Per face, the faces sharing an edge with it (ascending edge order; non-manifold edges give
// each of their faces all the others).
std::vector<std::vector<int>> face_neighbours(const Eigen::MatrixXi& F);

// The flipped faces of TransferMetrics (see header), ascending: A deformed, B its rest shape,
// neighbours = face_neighbours(F).
std::vector<int> flipped_faces(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXi& F,
                               const std::vector<std::vector<int>>& neighbours);

// The collapsed faces of TransferMetrics (see header), ascending: A deformed, B its rest shape.
std::vector<int> collapsed_faces(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXi& F);

// Aligned vertex error: mean_i |s R a_i + t − b_i| / D (D = bbox diagonal of B) after the
// least-squares similarity (Umeyama, linalg/rigid_fit.h) of A onto B, so that a global
// placement, orientation or size difference (e.g. a result kept at the source's size) does not
// count. A and B: #V by 3, same vertex order (assert).
double aligned_vertex_error(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B);

}  // namespace mm
