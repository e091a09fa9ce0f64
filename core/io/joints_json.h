// JSON readers of joint sets and joint maps (retarget inputs written by hand or by the page):
// {"joint name": [x, y, z], ...} and {"source joint": "target joint", ...}.
#pragma once

#include <map>
#include <string>

#include "character/joint_set.h"
#include "common/status.h"

namespace mm::io {

struct JointSetResult {
  Status status;   // ParseError with the offending key when the JSON is malformed
  JointSet joints;
};

// Parses {"name": [x, y, z], ...}. Joints come out sorted by name (JSON objects are unordered).
// from_user is set.
JointSetResult parse_joints_json(const std::string& text);

// Parses a joint map {"source joint name": "target joint name", ...}.
struct JointMapResult {
  Status status;
  std::map<std::string, std::string> source_to_target;
};
JointMapResult parse_joint_map_json(const std::string& text);

}  // namespace mm::io
