#include "cage/enclosing_cage.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "cage/cage_containment.h"
#include "cage/cage_detail.h"
#include "cage/hull_decimation.h"
#include "cage/offset_surface.h"
#include "mesh/mesh.h"
#include "mesh/validate.h"

namespace mm {

namespace enclosing_detail {

using cage_detail::Vec3;

// Vertices of V that are not strictly inside (winding ≠ 1 or closer than `clearance`).
std::vector<int> cage_failures(const CageContainment& c, double clearance) {
  std::vector<int> bad;
  for (int i = 0; i < c.winding.size(); ++i)
    if (c.winding[i] != 1 || c.distance[i] < clearance) bad.push_back(i);
  return bad;
}

// Pushes the cage faces nearest to the failing vertices outward along the cage vertex normals
// so that each failing vertex ends up ~2 clearances inside. Returns the number of moved vertices.
int push_cage_outward(const Eigen::MatrixXd& V, const std::vector<int>& bad, const CageContainment& cc,
                      double clearance, Eigen::MatrixXd* C, const Eigen::MatrixXi& CF) {
  const int nc = static_cast<int>(C->rows());
  std::vector<Vec3> cv(nc), normal(nc);
  for (int i = 0; i < nc; ++i) cv[i] = Vec3((*C)(i, 0), (*C)(i, 1), (*C)(i, 2));
  for (int f = 0; f < CF.rows(); ++f) {
    const Vec3 n = cage_detail::area_vector(cv[CF(f, 0)], cv[CF(f, 1)], cv[CF(f, 2)]);
    for (int k = 0; k < 3; ++k) normal[CF(f, k)] = normal[CF(f, k)] + n;
  }
  for (auto& n : normal) n = cage_detail::normalized(n);
  std::vector<double> push(nc, 0.0);
  for (int i : bad) {
    const Vec3 q(V(i, 0), V(i, 1), V(i, 2));
    int best_f = 0;
    double best = 1e300;
    for (int f = 0; f < CF.rows(); ++f) {
      const double d2 = cage_detail::point_triangle_distance2(q, cv[CF(f, 0)], cv[CF(f, 1)], cv[CF(f, 2)]);
      if (d2 < best) {
        best = d2;
        best_f = f;
      }
    }
    const double d = std::sqrt(best);
    const double amount = cc.winding[i] == 1 ? 2 * clearance - d + clearance : d + 3 * clearance;
    for (int k = 0; k < 3; ++k) push[CF(best_f, k)] = std::max(push[CF(best_f, k)], amount);
  }
  int moved = 0;
  for (int v = 0; v < nc; ++v)
    if (push[v] > 0) {
      ++moved;
      (*C)(v, 0) += push[v] * normal[v].x;
      (*C)(v, 1) += push[v] * normal[v].y;
      (*C)(v, 2) += push[v] * normal[v].z;
    }
  return moved;
}

}  // namespace enclosing_detail

EnclosingCage enclosing_cage(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                             const EnclosingCageOptions& opt, const Progress& progress) {
  EnclosingCage out;
  if (opt.target_vertices < 8) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "cage target of " + std::to_string(opt.target_vertices) + " vertices is too small (need >= 8)");
    return out;
  }
  const double diag = bounding_box_diagonal(V);
  if (V.rows() < 4 || F.rows() < 1 || !V.allFinite() || !(diag > 0)) {
    out.status = Status::error(StatusCode::InvalidMesh, "cannot build a cage around an empty or non-finite mesh");
    return out;
  }
  OffsetSurfaceOptions oo;
  oo.resolution = opt.resolution;
  oo.offset_voxels = opt.offset_voxels;
  OffsetSurface offset = offset_surface(V, F, oo, progress.sub(0.0, 0.35));
  if (!offset.status.ok()) {
    out.status = offset.status;
    return out;
  }
  out.offset_vertices = static_cast<int>(offset.V.rows());

  HullDecimationOptions ho;
  ho.target_vertices = opt.target_vertices;
  ho.max_normal_turn_deg = opt.max_normal_turn_deg;
  ho.length_weight = opt.length_weight;
  const double clearance = opt.min_clearance * diag;
  // Decimated in the offset grid's coordinates, where the offset surface is the same bit for bit
  // for copies of the mesh that differ in their last bits (cage/offset_surface.h): a voxel
  // surface has exact ties in its collapse costs, and in mesh units such noise broke them
  // differently (lion-reference: a relative 1e-12 of noise moved the cage by half the diagonal
  // and the lion-05 transfer by 0.155 of it). The cost and every test of the decimation are
  // invariant to a translation and a uniform scale.
  const double h = offset.voxel_size;
  const Eigen::RowVector3d origin = offset.grid_origin.transpose();
  const Eigen::MatrixXd P_grid = (V.rowwise() - origin) / h;
  HullDecimation dec = hull_decimation(offset.V_grid, offset.F, P_grid, clearance / h, ho, progress.sub(0.35, 0.9));
  if (!dec.status.ok()) {
    out.status = dec.status;
    return out;
  }
  out.collapses = dec.collapses;
  out.V = (h * dec.V).rowwise() + origin;
  out.F = std::move(dec.F);

  CageContainment cc = cage_containment(V, out.V, out.F, 10 * clearance);
  std::vector<int> bad = enclosing_detail::cage_failures(cc, clearance);
  for (int round = 0; round < opt.repair_rounds && !bad.empty(); ++round) {
    out.repaired_vertices += enclosing_detail::push_cage_outward(V, bad, cc, clearance, &out.V, out.F);
    cc = cage_containment(V, out.V, out.F, 10 * clearance);
    bad = enclosing_detail::cage_failures(cc, clearance);
  }
  if (!bad.empty()) {
    out.status = Status::error(StatusCode::NumericalError,
                               "automatic cage leaves " + std::to_string(bad.size()) + " of " +
                                   std::to_string(V.rows()) + " vertices outside or on it (first: vertex " +
                                   std::to_string(bad[0]) + "); raise the cage resolution or pass a cage");
    return out;
  }
  out.min_distance = cc.distance.size() ? cc.distance.minCoeff() : 0.0;
  if (!out.V.allFinite()) {
    out.status = Status::error(StatusCode::NumericalError, "cage has non-finite vertices");
    return out;
  }
  progress.update("cage", 1.0);
  return out;
}

Status check_user_cage(const Eigen::MatrixXd& V, const Eigen::MatrixXd& C, Eigen::MatrixXi* CF,
                       double min_clearance) {
  const MeshReport report = validate_mesh(C, *CF);
  Status s = report.status(manifold_defects());
  if (!s.ok()) return Status::error(StatusCode::InvalidMesh, "cage: " + s.message);
  if (!report.closed()) {
    return Status::error(StatusCode::InvalidMesh,
                         "cage is not closed: it has " + std::to_string(report.boundary_loops.size()) +
                             " boundary loop(s); mean-value coordinates need a closed cage");
  }
  const double clearance = min_clearance * bounding_box_diagonal(V);
  CageContainment cc = cage_containment(V, C, *CF, clearance);
  if (!cc.status.ok()) return cc.status;
  if (V.rows() > 0 && (cc.winding.array() == -1).all()) {
    // Inward-oriented cage: flip every face and count again.
    CF->col(1).swap(CF->col(2));
    cc = cage_containment(V, C, *CF, clearance);
  }
  if (!cc.not_inside.empty()) {
    return Status::error(StatusCode::InvalidMesh,
                         "cage encloses " + std::to_string(V.rows() - static_cast<long>(cc.not_inside.size())) +
                             " of " + std::to_string(V.rows()) + " vertices; first outside or on the cage: vertex " +
                             std::to_string(cc.not_inside[0]));
  }
  return Status::success();
}

}  // namespace mm
