// Linear blend skinning: per-vertex influences on a list of transforms (glTF skins, rigid parts
// parented to nodes, transferred skin weights of the LBS baseline).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/StdVector>

namespace mm {

// Per-vertex influences: up to K (transform index, weight) pairs; unused slots have weight 0.
struct SkinWeights {
  Eigen::MatrixXi index;   // #V by K transform indices
  Eigen::MatrixXd weight;  // #V by K weights, rows sum to 1
};

using Matrix4dList = std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>>;

// v' = Σ_k w_k M[index_k] · [v; 1]. V: #V by 3.
Eigen::MatrixXd linear_blend_skinning(const Eigen::MatrixXd& V, const SkinWeights& W, const Matrix4dList& M);

}  // namespace mm
