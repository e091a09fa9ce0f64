// Farthest-point sampling and roughly uniform surface samples, the two ingredients of the
// "furthest point relaxation" placement used by paper 002 Sec. 4.3 (after Jacobson et al.
// 2012, Fast Automatic Skinning Transformations) for singularity and collocation points.
//
// Both are deterministic: no randomness, ties broken by the lower index.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mm {

// Greedy farthest-point sampling of `count` rows of P (#P by 3). Starts at `first` (a row
// of P) and repeatedly adds the point farthest (Euclidean) from all chosen ones. Returns the
// chosen row indices in the order they were picked (so any prefix is itself a well-spread
// sample). count ≥ #P returns all rows (in picking order); exact duplicates are picked last.
// `min_distance` (optional out) is the smallest distance from a chosen point to the others
// when the last one was added — the sampling radius.
std::vector<int> farthest_point_sampling(const Eigen::MatrixXd& P, int count, int first = 0,
                                         double* min_distance = nullptr);

// Points on a triangle surface with about uniform density, as (face, barycentric) pairs.
struct SurfaceSamples {
  Eigen::VectorXi face;         // #S triangle index of each sample
  Eigen::MatrixXd barycentric;  // #S by 3 weights of F(face, 0..2)
  Eigen::MatrixXd P;            // #S by 3 positions
  Eigen::MatrixXd N;            // #S by 3 unit face normals (zero for degenerate faces)

  int size() const { return static_cast<int>(face.size()); }
  // Positions of the same samples on a deformed copy of the surface (same F, new V).
  Eigen::MatrixXd positions(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) const;
};

// At least ~`target_count` samples: every face gets the centroids of its 4^L midpoint
// subdivision triangles, with L chosen per face so that each sub-triangle has at most
// total_area / target_count area (L = 0: the centroid only). Degenerate faces get none.
// Also includes every vertex referenced by F (as a corner sample of its first face), so
// thin features and silhouettes are represented.
SurfaceSamples surface_samples(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int target_count);

// A subset of samples (rows `index`), in that order.
SurfaceSamples select_samples(const SurfaceSamples& S, const std::vector<int>& index);

}  // namespace mm
