// Metrics of motion retargeting (paper 002 Sec. 8.1): the self-retargeting / harmonic mapping
// error (Eq. 19), bone-length error of the target joints, self-intersections per frame, and the
// vertex error against a ground-truth animation.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

namespace mm {

struct SequenceError {
  Eigen::VectorXd per_frame;  // #frames: mean vertex distance of each frame / scale
  double mean = 0;            // mean over frames (Eq. 19 when the target is the source calibration)
  double max = 0;             // largest per-frame value
  double max_vertex = 0;      // largest single vertex distance / scale over all frames
};

// Per frame: mean_i ‖A_i − B_i‖ / scale (scale: the character's height for Eq. 19, which the
// paper normalises to 1). A and B hold the same number of frames of equally sized #V by 3 poses.
SequenceError sequence_vertex_error(const std::vector<Eigen::MatrixXd>& A, const std::vector<Eigen::MatrixXd>& B,
                                    double scale);

struct BoneLengthError {
  Eigen::VectorXd per_frame;  // #frames: mean_b |ℓ_b(t) − ℓ_b| / ℓ_b
  double mean = 0;            // mean over frames
  double max = 0;             // largest relative deviation of any bone in any frame
};

// Relative bone-length deviation of joint trajectories `joints` (per frame #J by 3) against the
// rest lengths `rest_lengths` of `bones` ((child, parent) joint indices).
BoneLengthError bone_length_error(const std::vector<Eigen::MatrixXd>& joints,
                                  const std::vector<std::pair<int, int>>& bones, const Eigen::VectorXd& rest_lengths);

// Number of pairs of triangles that intersect (Möller's triangle–triangle test), not counting
// pairs that share a vertex index. Pairs that already intersect in `rest` (multi-part
// characters interpenetrate by design) can be left out by passing the rest pose's pairs.
std::vector<std::pair<int, int>> intersecting_triangle_pairs(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);
int self_intersection_count(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                            const std::vector<std::pair<int, int>>& ignore = {});

}  // namespace mm
