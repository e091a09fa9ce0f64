// A GLB for viewing geometry overlays (skeletons, joints): line sets, point sets and an optional
// translucent surface, each its own node and colour. Used by `meshmorph joints --debug-skeleton`.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm::io {

struct DebugGeometry {
  std::string name;                          // node and mesh name
  Eigen::MatrixXd P;                         // #P by 3 positions
  std::vector<std::pair<int, int>> lines;    // segments between rows of P; empty = draw P as points
  Eigen::MatrixXi F;                         // #F by 3 triangles (a surface; lines must be empty)
  std::array<float, 4> color{1, 1, 1, 1};    // RGBA base colour (alpha < 1 blends)
};

// Writes every non-empty set as one primitive (LINES, POINTS or TRIANGLES) of its own mesh and
// node, with an unlit-looking flat material (no metalness). InvalidArgument on out-of-range
// indices or non-finite positions; IoError when serialization fails.
Status debug_geometry_glb(const std::vector<DebugGeometry>& sets, std::vector<uint8_t>* bytes);

}  // namespace mm::io
