// Landmark correspondence functions for coupled bases (paper 000 Sec. 5; Kovnatsky et al. 2013):
// indicator functions of k-ring neighbourhoods of corresponding vertices.
//
// k = reference_rings (3) on the reference; on the source k is chosen per landmark in
// 1..max_source_rings so that the region's normalized area (region area / surface area) best
// matches the reference region's. Each indicator is divided by its region's area, so that its
// A-inner product with a function is the function's mean over the region (a scale-free
// "point value"; the coupling term then compares like with like on meshes of any size).
//
// For same-connectivity pairs, landmarks can be generated: farthest-point samples under
// edge-length (Dijkstra) distance, starting from the vertex farthest from vertex 0.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "mesh/correspondence.h"

namespace mm {

struct LandmarkOptions {
  int reference_rings = 3;   // k on the reference (paper 000 Sec. 5: always 3)
  int max_source_rings = 8;  // source k is searched in 1..this (paper: usually 3, 4 or 5)
  int min_landmarks = 6;     // fewer pairs give InvalidArgument (the coupling is underdetermined)
  int auto_count = 30;       // generated landmarks for same-connectivity pairs (paper: p ≈ 30)
};

struct LandmarkFunctions {
  Status status;                 // InvalidArgument: index out of range, too few or repeated pairs
  Eigen::MatrixXd reference;     // #V' by p, normalized indicators on the reference
  Eigen::MatrixXd source;        // #V by p, normalized indicators on the source
  std::vector<int> source_rings; // p: the k chosen on the source for each pair
};

// Validates `pairs` against the mesh sizes (range, count, duplicates). Messages name the pair.
Status check_landmarks(const std::vector<LandmarkPair>& pairs, int reference_vertices, int source_vertices,
                       int min_landmarks);

// F_*: triangles; mass_*: lumped vertex areas (operators/operators.h).
LandmarkFunctions landmark_functions(const Eigen::MatrixXi& F_reference, const Eigen::VectorXd& mass_reference,
                                     const Eigen::MatrixXi& F_source, const Eigen::VectorXd& mass_source,
                                     const std::vector<LandmarkPair>& pairs, const LandmarkOptions& opt = {});

// `count` well-spread vertices (farthest-point sampling, see header), deterministic.
std::vector<int> farthest_point_landmarks(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int count);

}  // namespace mm
