// Rigid motions for props (weapons, helmets, capes hanging under joint nodes) of a character
// whose surface is animated some other way (retargeted frames exported as morph targets).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/StdVector>

#include "character/animated_character.h"

namespace mm {

// Props: meshes of a glTF character that are not part of its surface (weapons, helmets, capes)
// hanging under a joint node. The retargeted surface moves through morph targets, so a prop
// would stay where it is; instead its nearest joint ancestor gets a rigid motion per frame: the
// best rigid fit (Kabsch) from the rest surface to the frame of the vertices that joint
// dominates in the skin (or, when it dominates none, its nearest ancestor that does). A joint
// is left alone when a surface part hangs below it or when it is given by a matrix.
struct NodeTrack {
  int node = -1;                                   // the joint node that is animated
  std::vector<int> props;                          // prop nodes that follow it
  int anchor_joint = -1;                           // joint whose vertices define the motion
  std::vector<int> anchor_vertices;                // rows of V_rest
  std::vector<Eigen::Vector3d> translation;        // per frame, local T
  std::vector<Eigen::Quaterniond, Eigen::aligned_allocator<Eigen::Quaterniond>> rotation;  // per frame, local R
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> world;          // per frame, world matrix
};
std::vector<NodeTrack> prop_tracks(const AnimatedCharacter& c, const std::vector<Eigen::MatrixXd>& frames);

}  // namespace mm
