// Welding of coincident vertices: glTF splits vertices at UV/normal seams, so a primitive is
// not a connected surface until vertices at the same position are merged.
#pragma once

#include <Eigen/Core>

namespace mm {

struct WeldOptions {
  // Vertices closer than tolerance × bbox diagonal are merged. 0 merges exact duplicates only.
  double tolerance = 1e-7;
  // Faces that become degenerate (two corners welded together) are removed.
  bool drop_degenerate_faces = true;
};

struct WeldResult {
  Eigen::MatrixXd V;         // #W by 3 welded positions (the first original of each group)
  Eigen::MatrixXi F;         // faces over welded vertices (#F' ≤ #F)
  Eigen::VectorXi to_welded; // #V_original: welded index of every original vertex
  Eigen::VectorXi face_map;  // #F': original face index of every kept face
};

// Welded vertices are numbered in order of their first original vertex, so the result is
// deterministic and an already-welded mesh comes back unchanged.
WeldResult weld_vertices(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                         const WeldOptions& opt = {});

// Spreads per-welded-vertex values (e.g. new positions, #W by k) back to the original layout.
Eigen::MatrixXd unweld(const Eigen::MatrixXd& welded_values, const Eigen::VectorXi& to_welded);

}  // namespace mm
