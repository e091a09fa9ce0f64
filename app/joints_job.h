// The joints job: automatic joints for an unrigged target (issue 14). The source character's
// named joints are fitted onto the target's curve skeleton (retarget/joint_fitting.h), optional
// markers pin named joints; the result is the JSON that `retarget --target-joints` reads, and a
// debug GLB with the skeletons and joints as lines and points. Shared by the CLI
// (`meshmorph joints`), `retarget --target-joints auto`, the wasm binding and tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "app/option_schema.h"
#include "common/progress.h"
#include "common/status.h"
#include "io/asset.h"
#include "io/gltf_animation.h"
#include "retarget/joint_fitting.h"

namespace mm::app {

struct JointsJobOptions {
  JointFitOptions fit;                                        // skeleton and fitting (joint_fitting.h)
  io::SurfaceSelection surface = io::SurfaceSelection::Auto;  // which glTF primitives form each character
};

// Every option of the joints job; defaults from JointsJobOptions / JointFitOptions.
const OptionSchema<JointsJobOptions>& joints_options();

struct JointsJobResult {
  Status status;
  JointFitResult fit;                 // joints (source names, target coordinates), skeletons, warnings
  Eigen::MatrixXd target_V;           // the target surface the joints were fitted in (#V by 3)
  Eigen::MatrixXi target_F;
  std::string json;                   // {"name": [x, y, z], ...} in the source's joint order
  std::vector<std::string> warnings;  // loading and fitting warnings
};

// source: a skinned glTF (its rest pose and joints). target: glTF or mesh file. markers_json:
// {"joint name": [x, y, z]} in target coordinates, or "".
JointsJobResult run_joints_job(const io::Asset& source, const io::Asset& target, const std::string& markers_json,
                               const JointsJobOptions& opt = {}, const Progress& progress = {});

// {"name": [x, y, z], ...} with 9 significant digits, in the set's order.
std::string joints_json_text(const JointSet& joints);

}  // namespace mm::app
