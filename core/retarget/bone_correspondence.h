// bone_correspondence: corresponding points between two characters from their matched bones
// ("bone coordinates"), used to spread the affine descriptors of paper 002 Eq. 5 from the joints
// to points near the surface.
//
// A target point y is attached to the nearest target bone (segment parent→child) that it sees
// without crossing the surface, at parameter u ∈ [0, 1] along it with radial offset o. Its source
// counterpart is the point at the same u on the matched source bone, in the direction of o turned
// by the rotation between the two rest bones, at the same fraction of the source's radius in that
// direction (found by casting rays to both surfaces; crossings of buried layers of
// interpenetrating parts are counted alike on both). Identical characters get x = y.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "spatial/triangle_bvh.h"

namespace mm {

struct BoneCorrespondence {
  Eigen::MatrixXd X;       // #Y by 3 source points
  Eigen::VectorXi bone;    // #Y bone index used (-1 when no bone fits: the row is invalid)
  Eigen::VectorXd u;       // #Y parameter along the bone
};

// Y: #Y by 3 target points; bones: (child, parent) rows into Jt/Js (#J by 3 rest joints of
// target and source, same order). bvh_t / bvh_s: the rest surfaces. Y must lie on the target
// surface.
BoneCorrespondence bone_correspondence(const Eigen::MatrixXd& Y, const std::vector<std::pair<int, int>>& bones,
                                       const Eigen::MatrixXd& Jt, const Eigen::MatrixXd& Js,
                                       const TriangleBvh& bvh_t, const TriangleBvh& bvh_s);

}  // namespace mm
