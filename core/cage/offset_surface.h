// Outer offset surface of a triangle mesh, on a voxel grid: the closed, consistently oriented
// 2-manifold {x : dist(x, solid) = d}, where `solid` is the voxelised volume enclosed by the
// mesh. The first stage of the automatic cage (cage/enclosing_cage.h).
//
// Steps: triangles are sampled onto grid nodes (every sample marks the 8 corners of its cell,
// so the marked shell is 6-connected-tight and closes holes and cracks smaller than a voxel);
// the exterior is flood-filled from the grid border; solid = not exterior (so non-manifold,
// inconsistently oriented or slightly open input is fine); an exact Euclidean distance
// transform (Felzenszwalb & Huttenlocher 2012) gives the distance to the solid; pockets of the
// outside that the offset closes off are filled; marching tetrahedra (6 Kuhn tetrahedra per
// cell, consistent across cells) extracts the level set d. Output triangles face outward
// (counter-clockwise seen from outside, mesh/mesh.h).
//
// Every point of the input surface lies within ~√3·h of a solid node, so the surface lies at
// least d − 2·h inside the offset surface (h = voxel size; the interpolation error of the
// level set is below h). The default d = 3h therefore encloses the input with a margin.
//
// Stable under last-bit noise of the input: the grid's origin sits half a voxel off the
// bounding box's planes (extreme vertices never lie on a grid plane, where floor() would send
// them to one cell or the next by their last bits), and the surface is also returned in grid
// coordinates (V_grid), where it depends only on which nodes are solid — the distance transform
// is exact in voxel units — so copies of a mesh that differ in their last bits give the same
// V_grid bit for bit. Consumers that must be deterministic (cage/enclosing_cage.h) work there.
#pragma once

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

struct OffsetSurfaceOptions {
  double voxel_size = 0;        // h in mesh units; 0 = longest bbox side / resolution
  int resolution = 96;          // grid cells along the longest bbox side when voxel_size = 0
  double offset_voxels = 3.0;   // d / h: offset distance in voxels (≥ 2.5 keeps the input inside)
  long max_grid_nodes = 16'000'000; // refuse grids larger than this (memory guard) with InvalidArgument
};

struct OffsetSurface {
  Status status;          // InvalidMesh for an empty/non-finite input, InvalidArgument for a bad grid
  Eigen::MatrixXd V;      // #W by 3 vertices of the offset surface = grid_origin + voxel_size · V_grid
  Eigen::MatrixXd V_grid; // #W by 3, the same vertices in grid coordinates (node index units)
  Eigen::Vector3d grid_origin = Eigen::Vector3d::Zero();  // position of grid node (0, 0, 0)
  Eigen::MatrixXi F;      // #T by 3 outward-oriented triangles
  double voxel_size = 0;  // h actually used
  double offset = 0;      // d actually used (mesh units)
};

// V: #V by 3 input positions, F: #F by 3 triangles (any topology).
OffsetSurface offset_surface(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                             const OffsetSurfaceOptions& opt = {}, const Progress& progress = {});

}  // namespace mm
