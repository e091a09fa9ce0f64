// Opening a closed mesh so that it can be merged (paper 001 Sec. 5 needs open boundaries):
// a plane cut that keeps the side a point is on, and a geodesic-disk cut that removes a disk.
//
// Both return a new mesh (vertices renumbered, unreferenced ones dropped) plus, per output
// vertex, the input vertex it came from (-1 for vertices created on the cut plane), so that
// landmarks and key vertices picked on the input can be mapped.
//
// Errors: InvalidArgument (non-finite or zero plane normal, keep point on the plane, disk vertex
// out of range, radius ≤ 0), InvalidMesh (empty input, nothing left on the kept side, the disk
// covers the whole mesh).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct CutResult {
  Status status;
  Eigen::MatrixXd V;           // #V' by 3
  Eigen::MatrixXi F;           // #F' by 3, orientation of the input
  std::vector<int> from;       // per output vertex: input vertex, or -1 when created by the cut
  int boundary_loops = 0;      // boundary loops of the result
};

struct PlaneCutOptions {
  // Input vertices closer to the plane than this fraction of the mean edge length are moved
  // onto it, so the cut never leaves sliver triangles. 0 = exact cut.
  double snap_fraction = 0.2;
};

// Keeps the part of the mesh on the side of the plane (point p, normal n) where `keep` lies,
// and of that part the connected piece nearest to `keep`. Faces crossing the plane are clipped
// (new vertices on the plane, quads split along their shorter diagonal).
CutResult cut_plane(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::Vector3d& p,
                    const Eigen::Vector3d& n, const Eigen::Vector3d& keep, const PlaneCutOptions& opt = {});

// Removes every face with a vertex closer than `radius` (geodesic distance along edges) to
// vertex `center`, then every face at a vertex the hole touches twice, so that the hole is one
// clean loop. Keeps the largest connected piece that remains.
CutResult cut_disk(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int center, double radius);

// Drops unreferenced vertices: V' = V(used), F renumbered; *from gets the input index of each
// output vertex (composed with *from when it already holds one entry per input vertex).
void compact_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, Eigen::MatrixXd* Vout,
                  Eigen::MatrixXi* Fout, std::vector<int>* from);

}  // namespace mm
