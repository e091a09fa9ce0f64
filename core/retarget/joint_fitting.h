// joint_fitting: places a source character's named joints inside an unrigged target mesh
// (automatic joints for paper 002's retargeting, Sec. 3), by fitting the source skeleton onto the
// target's curve skeleton (retarget/curve_skeleton.h).
//
// Steps:
//  1. curve skeletons of both rest shapes (same options, so both sides are cut alike);
//  2. up direction: the source's is given (glTF +Y); the target's is the signed axis with the
//     most limb ends (skeleton leaves) near its low end — feet stand on the ground — unless given;
//  3. facing (unless given, e.g. +z for glTF by its spec): the 4 axis-aligned turns about up are scored by the chamfer distance between the two
//     solids (normalised: feet at 0, height 1, centred) plus the distance of matched limb ends
//     (an unmatched end on either side costs leaf_tolerance: a quadruped turned back to front
//     still pairs its legs, but leaves both heads unmatched);
//  4. limb ends are matched greedily by normalised position of the end and of a point back_length
//     up its path (≤ leaf_tolerance × height apart), so A- and T-poses pair hands with hands;
//     a second pass pairs source limbs that carry joints and are still unmatched with the
//     target's unmatched limbs by where they join the matched body and where their middles lie
//     (match_by_attachment: hanging arms against a T-pose, with a warning);
//     a source limb end that carries joints with no match is a topology mismatch, and so is a
//     different number of limbs on the ground (biped vs quadruped);
//  5. each source joint is located on the source skeleton (closest point q on the paths between
//     matched limb ends) and described, for every pair (a, b) of matched ends whose path holds q,
//     by the segment of that path between consecutive branch points (medians of a, b and another
//     matched end c) and its fraction along it; the same labelled segment of the target path
//     a′–b′ at the same fraction gives a target point (proportions along branches). The target
//     joint is the mean over pairs plus the joint's offset from q, turned into the target's axes
//     and scaled by the ratio of the local radii. A marker lying near a target path (marker_anchor)
//     is one more pair of corresponding positions on it beside the branch points: the joints of a
//     marked chain are spread between the marker and the branch points around it;
//  5b. each joint is then moved by the local affine map that takes the source surface around it
//     (posed onto the fitted joints bone by bone) to its closest target points — a joint centred
//     in a thigh stays centred in a thicker one; a few rounds, each move at most twice the
//     joint's depth (measured: Knight's joints in Barbarian 0.78 → 0.60 % of the height); the
//     surface around a joint is what it sees through the source's solid (not the other leg);
//  5d. a target built of separate parts bends at its ball parts (small closed round parts: a robot's
//     or a mannequin's ball joints); a fitted joint that has reached one (each the other's nearest,
//     within ball_joint_reach radii) moves to its centre — plus the source joint's offset from its
//     own ball where the source has ball parts too, so a self fit stays exact;
//  5e. a joint across a limb moves, along the front axis, to its source joint's fraction of the
//     limb's depth (where both rays leave the body at their first hit and the depths compare);
//     a joint on the middle where limbs branch off to both sides (hips, chest) moves sideways to
//     the middle of the target's section plus the source joint's own offset from the middle;
//  5f. a target that is its own mirror image gets mirror-image joint pairs: each joint with a mirror
//     partner in the source becomes the mean of itself and its partner's mirror image, plus half
//     the source's own asymmetry (a self fit stays exact);
//  6. a joint outside the target is pulled toward its skeleton point until inside; markers pin
//     named joints and drag their chain neighbours (weights fall off over marker_reach joints).
// Source joints outside the source surface (roots on the floor, IK targets) are not placed.
//
// Status: InvalidMesh (from the skeletons: empty, flat, broken mesh), InvalidArgument (a marker
// names no source joint or lies outside the target; a topology mismatch, with the limb counts and
// what to pass), Cancelled. Deterministic.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "character/joint_set.h"
#include "common/progress.h"
#include "common/status.h"
#include "retarget/ball_parts.h"
#include "retarget/curve_skeleton.h"

namespace mm {

// Which tree stands for the source in steps 4–5.
// Voxel: both sides are cut alike, so proportions along branches compare (self-fits ≤ 1% of the
// height). Bones fits sources whose curve skeleton has far more limb ends than their rig
// (KayKit's blocky parts: 24 ends for 5 limbs), which Voxel refuses as a topology mismatch;
// measured KayKit Knight → human_woman: 6.9% of the height from the hand-placed joints (13% before
// the back points stopped at half the limb and her touching legs were split). Bones as the only mode is worse where
// Voxel fits (Knight self-fit 3%, Fox → wolf0 12% vs 8.7%), hence Auto.
enum class SourceSkeleton {
  Auto,    // Voxel; where a source limb finds no partner in the target, Bones (with a warning)
  Voxel,   // the source's curve skeleton, cut like the target's (both sides measured alike)
  Bones,   // the source's own joint tree (joints inside its surface), each leaf bone prolonged
           // along its direction to the surface (the limb's tip)
};

struct JointFitOptions {
  CurveSkeletonOptions skeleton;  // both shapes' skeletons (the source's volume is always voxelised)
  SourceSkeleton source_skeleton = SourceSkeleton::Auto;
  int source_up = 1;              // source up axis: 0..2 = +x,+y,+z, 3..5 = −x,−y,−z (glTF: 1)
  int target_up = -1;             // target up axis as source_up; −1 = detect from the limb ends
  int source_front = 2;           // source facing axis, as source_up (glTF: +z)
  int target_front = -1;          // target facing axis; −1 = detect (step 3)
  double leaf_tolerance = 0.6;    // limb ends match when ≤ this × height apart (normalised shapes; mean of
                                  // the ends' and the back points' distances)
  bool match_by_attachment = true; // step 4's second pass: source limbs left unmatched (carrying joints) pair
                                   // with the target's by where they join the body (poses unlike: hanging vs spread arms)
  double back_length = 0.25;      // back point of a limb end: this × height up its path (pose-robust matching),
  double back_limb_fraction = 0.5; // but at most this × the limb's length to its first branch point
  double ground_band = 0.12;      // limb ends below this × height count as standing on the ground
  double ground_step = 0.04;      // ... and within this × height of the lowest limb end (a hand hanging low is no foot)
  double min_up_extent = 0.3;     // a detected up axis spans at least this × the longest extent
  double inside_tolerance = 0.01; // a joint within this × bbox diagonal outside the surface counts as inside
  double touching_legs_groove = 0.95;// biped target: trunk nodes above the leg fork whose front-to-back thickness
                                   // between the legs is below this × through each leg are thighs that touch;
                                   // the legs are split up to the first node without that groove (0 = off)
  int surface_refine_iterations = 3; // step 5b: joints moved by the local affine map of the surfaces around them (0 = off)
  double surface_refine_sigma = 2.5; // its neighbourhood: Gaussian σ = this × the joint's depth below the source surface
  double surface_refine_ridge = 0.1; // its affine fit's ridge toward a pure translation, × the neighbourhood's spread
  bool surface_refine_seen = true;   // ... only the surface seen from the joint through the source's solid (not a
                                     // neighbouring limb across empty space)
  double surface_refine_max_move = 2;// a joint moves at most this × its depth inside the target (≥ 0.01 × height)
  double skeleton_prior = 2;       // step 5c: weight of the source's bones (scaled into the target) against the fit (0 = off)
  double skeleton_prior_agreement = 0.15;  // ... full while the fitted bones differ from those by ≤ this (Σ|d − b| / Σ|b|),
                                   // fading to 0 at 1.6 × this (a target of the source's rig family)
  double offset_cap = 2.5;         // step 5: unless the target is of the source's rig family (the skeleton prior's gate),
                                  // a joint's offset from its skeleton point is at most this × the source radius there (0 = off)
  double ball_joint_reach = 3;    // step 5d: a fitted joint within this × a ball part's radius of its centre (each the
                                  // other's nearest) moves there, plus its source joint's offset from its own ball if the
                                  // source has one (0 = off)
  BallPartOptions balls;          // ... what counts as a ball part (retarget/ball_parts.h)
  double mirror_symmetry = 0.01;  // step 5f: where source and target surfaces mirrored across their middle planes lie
                                  // within this × height of themselves (mean), the fitted joint pairs are made mirror
                                  // images, up to the source's own asymmetry (0 = off)
  double depth_span_ratio = 2;    // step 5e: a joint across a limb moves to its source joint's fraction of the limb's
                                  // front-to-back depth where the two depths (scaled) are within this ratio (≤ 1 = off)
  double middle_span_ratio = 3;   // step 5e: a joint on the source's middle plane where limbs branch off to both sides
                                  // moves sideways to the middle of the target's section plus the source joint's offset
                                  // from its own, where the two widths (scaled) are within this ratio (≤ 1 = off)
  int marker_reach = 3;           // markers move unpinned joints up to this many bones away (0 = only pin)
  double marker_anchor = 0.1;     // step 5: a marker within this × height of a target path between matched ends
                                  // anchors the proportions along it (0 = off)
  bool check_topology = true;     // refuse a mismatch (step 4); false = fit whatever matches
};

struct JointMarker {
  std::string name;               // a source joint name
  Eigen::Vector3d position;       // target coordinates
};

struct JointFitResult {
  Status status;                  // check ok() first
  JointSet joints;                // source names (joints inside the source), target positions, hierarchy
  std::vector<std::string> skipped;   // source joints not placed (outside the source surface)
  std::vector<std::string> warnings;
  CurveSkeleton source_skeleton, target_skeleton;
  SourceSkeleton source_tree = SourceSkeleton::Voxel;  // the tree the result was fitted on (Voxel or Bones)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // target axes → source axes (axis-aligned)
  int target_up = 1;              // detected or given up axis of the target (as JointFitOptions)
  std::vector<std::pair<int, int>> limb_ends;  // matched leaves (source node, target node)
  int source_ground = 0, target_ground = 0;    // limb ends on the ground (step 4)
  double skeleton_agreement = 0;  // step 5c: Σ|d − b| / Σ|b| of the fitted bones d against the source's b
  double skeleton_prior_used = 0; // the prior's weight after that gate (0: not applied)
  std::vector<std::string> ball_joints;  // step 5d: joints moved to the centre of a ball part of the target
  int depth_moved = 0;            // step 5e: joints moved to their source joint's fraction of the depth
  int middle_moved = 0;           // step 5e: middle joints moved sideways to the middle of the target's section
  int mirrored = 0;               // step 5f: joints set from themselves and their mirror partner (symmetric target)
};

// Vs/Fs: source rest surface; source_joints: its joints (names, positions, parents).
// Vt/Ft: target surface (any triangle soup). markers: may be empty.
JointFitResult fit_joints(const Eigen::MatrixXd& Vs, const Eigen::MatrixXi& Fs, const JointSet& source_joints,
                          const Eigen::MatrixXd& Vt, const Eigen::MatrixXi& Ft,
                          const std::vector<JointMarker>& markers = {}, const JointFitOptions& opt = {},
                          const Progress& progress = {});

}  // namespace mm
