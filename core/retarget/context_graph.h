// context_graph: the Context Graph of paper 002 Sec. 6 — surface nodes (the MFS singularities
// projected onto the source calibration surface), body parts by k-means seeded at the joints,
// and the complete graph pruned by the three rules of Sec. 6.1:
//   (1) both ends in the same body part → removed,
//   (2) longer than max_edge_length × the calibration height → removed,
//   (3) the segment passes through the interior of the surface → removed.
// Plus the uniform graph Laplacian L = I − Diag⁻¹·Adjacent of Sec. 6.2 (Eq. 11, 12).
//
// Conventions: V #V by 3, F #F by 3 (mesh/mesh.h); "height" is the extent along up_axis.
// Deterministic: k-means starts at the joints and iterates a fixed number of times in index
// order; edges are emitted as (i < j) in lexicographic order.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "spatial/triangle_bvh.h"

namespace mm {

struct ContextGraphOptions {
  double max_edge_length = 0.5;   // rule (2): edges longer than this × the calibration height are
                                  // removed (paper Sec. 6.1: "50% of the calibration shape height")
  int kmeans_iterations = 10;     // Lloyd iterations of the body-part clustering (Sec. 6.1 (1))
  int up_axis = 1;                // axis whose extent is the height (glTF: +Y)
  double segment_margin = 1e-4;   // rule (3): the segment is shortened by this × the bbox
                                  // diagonal at both ends, so that its endpoints (on the surface)
                                  // do not count as crossings
};

// Body parts (Sec. 6.1 (1)): k-means of the points P (#P by 3) with one center per joint
// (#J by 3), seeded at the joints. `label` (#P) holds each point's part (a joint index);
// `centers` (#J by 3) the final centers (a center that loses all its points stays put).
struct BodyParts {
  Eigen::MatrixXd centers;
  Eigen::VectorXi label;
};
BodyParts body_parts(const Eigen::MatrixXd& P, const Eigen::MatrixXd& joints, int iterations = 10);
// Index of the nearest center for each row of X (ties to the lower index).
Eigen::VectorXi nearest_centers(const Eigen::MatrixXd& X, const Eigen::MatrixXd& centers);

// Graph nodes on a surface: each point of Q (e.g. the singularities, outside the surface)
// projected to its closest surface point. Projections closer than `merge_distance` to an earlier
// node are dropped (two singularities above the same spot), so nodes are distinct.
struct SurfaceNodes {
  Eigen::VectorXi face;         // #N triangle of each node
  Eigen::MatrixXd barycentric;  // #N by 3 weights of F(face, 0..2)
  Eigen::MatrixXd P;            // #N by 3 positions
  Eigen::VectorXi source;       // #N row of Q each node came from
  int size() const { return static_cast<int>(face.size()); }
  // Positions of the same nodes on a deformed copy of the surface (same F, new V).
  Eigen::MatrixXd positions(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) const;
};
SurfaceNodes project_to_surface(const Eigen::MatrixXd& Q, const TriangleBvh& bvh, double merge_distance);

// Which rule removed an edge (for counts and tests).
struct PruneCounts {
  int complete = 0;     // n(n−1)/2 candidate edges
  int same_part = 0;    // removed by rule (1)
  int too_long = 0;     // removed by rule (2) (among those not removed by (1))
  int interior = 0;     // removed by rule (3) (among those left)
  int kept = 0;
};

// Edges (i < j, lexicographic) of the complete graph over the rows of P (#N by 3, points on the
// surface of `bvh`) that survive the three rules; `part` (#N) are the nodes' body parts and
// `height` the calibration height (rule 2 uses max_edge_length × height). Rule (3): the segment
// (shortened by segment_margin at both ends) crosses a triangle, or its midpoint is inside.
std::vector<std::pair<int, int>> pruned_context_edges(const Eigen::MatrixXd& P, const Eigen::VectorXi& part,
                                                      const TriangleBvh& bvh, double height,
                                                      const ContextGraphOptions& opt = {}, PruneCounts* counts = nullptr);

// Uniform graph Laplacian L = I − Diag⁻¹·Adjacent (n by n, Sec. 6.2): row i is zero for an
// isolated node. L·1 = 0; not symmetric.
Eigen::SparseMatrix<double> uniform_graph_laplacian(int n, const std::vector<std::pair<int, int>>& edges);

// Sorted union of edge lists (each (i < j)).
std::vector<std::pair<int, int>> edge_union(const std::vector<std::pair<int, int>>& a,
                                            const std::vector<std::pair<int, int>>& b);

}  // namespace mm
