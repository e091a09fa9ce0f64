// Normals of corner groups: the unit sum of the area-weighted normals of the triangles whose
// corners belong to each group (io-internal).
//
// A group is "the corners that share one stored normal": an OBJ `vn` index, or a glTF/PLY
// vertex. Recomputing a stored normal this way keeps the file's smoothing: a vertex split at a
// hard edge has one group per side, and each side gets only its own faces' normals.
#pragma once

#include <Eigen/Core>

namespace mm::io {

// V: #V by 3; F: #F by 3; G: #F by 3 group id of each corner (-1: no group); num_groups.
// Returns num_groups by 3; groups with no non-degenerate face keep a zero row.
Eigen::MatrixXd grouped_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                const Eigen::MatrixXi& G, int num_groups);

}  // namespace mm::io
