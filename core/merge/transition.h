// Transition regions across a merge seam (paper 001 Sec. 5.3, in the form described in
// docs/merge.md): the details of both meshes blend smoothly across the seam instead of being
// filtered by the umbrella operator.
//
// On the zipped mesh, the transition region is every target-side vertex within `target_width`
// (geodesic, along edges) of the seam and every source-side vertex within `source_width`. Each
// side is parameterized over the unit square — u: arc length along the seam (cut at the first key
// pair, as the paper cuts along the shortest path between two keys), v: distance from the seam /
// width — so that a point of one side corresponds to the point of the other side with the same
// (u, v). The Laplacian coordinate of every region vertex becomes the linear blend
//   δ_i = (1 − s_i) δ^target(u_i, v_i) + s_i δ^source(u_i, v_i),
// s_i running from 0 at the region's target edge to 1 at its source edge, where the coordinate
// of the side a vertex is not on is interpolated (barycentric) from the other side's triangles in
// the (u, v) square. The region is then rebuilt from the blended coordinates on the zipped
// mesh's connectivity (one cotangent Poisson solve, the region's outer edges fixed).
//
// Differences from the paper, stated: the two regions lie on both sides of the seam rather than
// overlapping (our merge lands the source's boundary on the target's), and the coupling term E_T
// of the optimization is replaced by this reconstruction alone (the paper's last step).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct TransitionSeam {
  std::vector<int> target_side;  // seam vertices on the target side (merged indices), along the seam
  std::vector<int> source_side;  // seam vertices on the source side, along the seam, [0] facing target_side[0]
};

struct TransitionReport {
  int region_vertices = 0;
  int fallback_lookups = 0;  // (u, v) points found by nearest vertex instead of a triangle
};

// V is modified in place. first_source: merged vertices ≥ this index are source-side.
// H (#V by 3): per merged vertex, the mean-curvature normal (Voronoi-area-normalized Laplacian
// coordinate) of the surface it came from — the original target with its band, the deformed
// source — so that neither the zip strip nor the two sides' different resolutions enter the
// blend. The blended coordinate of vertex i is A_i · H_blend(i) with A_i its Voronoi area on the
// zipped mesh. Widths in mesh units (> 0).
Status blend_transition(Eigen::MatrixXd* V, const Eigen::MatrixXi& F, int first_source,
                        const std::vector<TransitionSeam>& seams, double target_width, double source_width,
                        const Eigen::MatrixXd& H, TransitionReport* report);

}  // namespace mm
