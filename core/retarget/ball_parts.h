// ball_parts: the balls of a character's ball joints — small, closed, round parts of a mesh built
// from separate parts (RobotExpressive's hips, elbows, neck and ankles; wooden mannequins, dolls,
// action figures are modelled the same way). joint_fitting (step 5d) moves a fitted joint to the
// centre of the ball it has reached, since that is where such a character bends.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace mm {

struct BallPart {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // centroid of the enclosed volume
  double radius = 0;                                  // of the sphere of the same volume
  double roundness = 0;                               // sphericity π^(1/3) (6 vol)^(2/3) / area: 1 for a sphere
};

struct BallPartOptions {
  double max_size = 0.1;        // a ball's largest extent is at most this × the character's height
  double min_roundness = 0.9;   // sphericity (an 80-triangle icosphere: 0.98; a cube: 0.81; a cylinder as
                                // tall as wide: 0.87)
  double weld_tolerance = 1e-7; // × bbox diagonal: glTF splits a part's vertices at its UV seams
};

// The parts (connected through shared edges once coincident vertices are welded) that are closed
// (every edge has exactly two faces), round and small, in order of their smallest vertex.
// `height` is the character's size (joint fitting: its longest side) in units of V. Empty for a single-part mesh.
std::vector<BallPart> ball_parts(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double height,
                                 const BallPartOptions& opt = {});

// Pairs balls with joints: ball b gets joint i when each is the other's nearest, they are at most
// reach × the ball's radius apart, and the ball lies clearly on i's side of each bone at i (its
// projection onto the bone from i to its parent or a child falls short of 0.4 of the bone): a ball
// near the middle of a fitted bone is left to neither joint (KayKit Knight's arm fitted short in
// RobotExpressive: the elbow ball at 0.44 of the upper arm). -1 otherwise. parent:
// one entry per row of P (-1: a root; empty: no bones). Joints with a non-finite row take no part.
std::vector<int> pair_balls_with_joints(const std::vector<BallPart>& balls, const Eigen::MatrixXd& P,
                                        const std::vector<int>& parent, double reach);

}  // namespace mm
