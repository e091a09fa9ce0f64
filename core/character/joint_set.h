// Joints of a character at its calibration pose (character tier: no file format, no algorithm), and the matching of source joints to target
// joints (paper 002 Sec. 3: "a sparse set of joints inside the source and target calibration
// shapes", from a skeleton or placed by the user).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct JointSet {
  std::vector<std::string> names;  // #J unique names
  Eigen::MatrixXd P;               // #J by 3 positions at the calibration pose (world units)
  std::vector<int> parent;         // #J parent joint index, -1 for roots; empty = unknown hierarchy
  bool from_user = false;          // placed by hand (JSON): mistakes are errors, not warnings

  int size() const { return static_cast<int>(names.size()); }
  int find(const std::string& name) const;  // index or -1
};

struct JointPair {
  int source = -1;  // index in the source JointSet
  int target = -1;  // index in the target JointSet
};

struct JointMatchResult {
  Status status;                   // InvalidArgument with the names when matching fails
  std::vector<JointPair> pairs;    // sorted by source index
  std::vector<std::string> warnings;
};

// Matches joints by the explicit map first, then by exact name, then by name ignoring case and
// the characters " _-.:" (e.g. "Hips" ~ "hips", "mixamorig:LeftArm" is not stripped).
// Errors (status not ok):
//  - a map entry names a joint that does not exist on its side;
//  - the target joints come from the user and one of them matches no source joint;
//  - fewer than `min_pairs` pairs result.
JointMatchResult match_joints(const JointSet& source, const JointSet& target,
                              const std::map<std::string, std::string>& source_to_target = {},
                              int min_pairs = 2);

// Depth of each joint in its hierarchy (0 for roots); all 0 when parents are unknown.
std::vector<int> joint_depths(const JointSet& joints);

}  // namespace mm
