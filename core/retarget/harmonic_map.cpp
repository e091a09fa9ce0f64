#include "retarget/harmonic_map.h"

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>

#include "common/threads.h"
#include "mesh/mesh.h"
#include "retarget/mfs_kernel.h"
#include "spatial/triangle_bvh.h"

namespace mm {

SingularityResult singularity_points(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                     const SingularityOptions& opt) {
  SingularityResult r;
  const double diag = bounding_box_diagonal(V);
  if (V.rows() == 0 || F.rows() == 0 || !(diag > 0)) {
    r.status = Status::error(StatusCode::InvalidMesh, "cannot place singularity points: the surface is empty");
    return r;
  }
  const TriangleBvh bvh(V, F);
  const SurfaceSamples S = surface_samples(V, F, opt.candidates);
  // Spread the candidate seeds first so that the work does not depend on the mesh density.
  const std::vector<int> seeds = farthest_point_sampling(S.P, opt.candidates, 0);
  // Each seed's two offset candidates are independent: computed in blocks of seeds across the
  // task threads (common/threads.h) into per-seed slots, then kept in seed order.
  const long ns = static_cast<long>(seeds.size());
  std::vector<Eigen::Vector3d> slot(2 * seeds.size());
  std::vector<double> slot_clearance(2 * seeds.size(), -1.0);  // < 0: no candidate on that side
  parallel_blocks(ns, 64, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      const int s = seeds[static_cast<size_t>(k)];
      const Eigen::Vector3d p = S.P.row(s).transpose(), n = S.N.row(s).transpose();
      if (!(n.squaredNorm() > 0)) continue;
      for (int side = 0; side < 2; ++side) {
        // The largest offset that fits on this side: thin gaps get smaller offsets instead of none.
        double o = opt.offset * diag;
        for (int level = 0; level <= opt.offset_levels; ++level, o *= 0.5) {
          const Eigen::Vector3d c = p + (side == 0 ? 1.0 : -1.0) * o * n;
          const ClosestPoint cp = bvh.closest_point(c);
          if (cp.sq_distance < 0.64 * o * o) continue;
          if (bvh.inside(c)) break;  // a smaller offset on the same side is inside as well
          slot[static_cast<size_t>(2 * k + side)] = c;
          slot_clearance[static_cast<size_t>(2 * k + side)] = std::sqrt(cp.sq_distance);
          break;
        }
      }
    }
  });
  std::vector<Eigen::Vector3d> cand;
  std::vector<double> clearance;
  cand.reserve(slot.size());
  for (size_t i = 0; i < slot.size(); ++i)
    if (slot_clearance[i] >= 0) cand.push_back(slot[i]), clearance.push_back(slot_clearance[i]);
  if (cand.empty()) {
    r.status = Status::error(StatusCode::InvalidMesh,
                             "cannot place singularity points: no offset point lies outside the surface");
    return r;
  }
  Eigen::MatrixXd C(cand.size(), 3);
  for (size_t i = 0; i < cand.size(); ++i) C.row(i) = cand[i].transpose();
  const std::vector<int> pick = farthest_point_sampling(C, opt.count, 0);
  r.Q.resize(pick.size(), 3);
  r.min_clearance = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < pick.size(); ++i) {
    r.Q.row(i) = C.row(pick[i]);
    r.min_clearance = std::min(r.min_clearance, clearance[pick[i]]);
  }
  return r;
}

namespace {

// V rounded to a power-of-two grid of ~1e-9 × its bounding-box diagonal. The sampling below is
// made of discrete choices (farthest points, inside tests), so a last-bit difference of the input
// (a skinned calibration pose evaluated with another libm, natively vs in wasm) could pick other
// points and move the result by percents; on the grid both platforms see the same numbers.
Eigen::MatrixXd snapped_to_grid(const Eigen::MatrixXd& V) {
  const double diag = bounding_box_diagonal(V);
  if (!(diag > 0) || !std::isfinite(diag)) return V;
  const double q = std::ldexp(1.0, static_cast<int>(std::floor(std::log2(1e-9 * diag))));
  return (V / q).array().round().matrix() * q;
}

}  // namespace

Status MfsHarmonicMap::build(const Eigen::MatrixXd& V_in, const Eigen::MatrixXi& F,
                             const HarmonicMapOptions& opt, const Progress& progress) {
  if (!progress.update("singularities", 0)) return cancelled_status("singularities");
  const Eigen::MatrixXd V = snapped_to_grid(V_in);
  SingularityResult sr = singularity_points(V, F, opt.singularities);
  if (!sr.status.ok()) return sr.status;
  Q_ = std::move(sr.Q);
  if (!progress.update("collocation", 0.3)) return cancelled_status("collocation");
  SurfaceSamples all = surface_samples(V, F, 2 * opt.num_collocation);
  {
    // Multi-part characters overlap (an arm primitive reaches into the torso): surface buried
    // inside another part is not a boundary of the shape, and fitting it would force the map to
    // follow both parts at once. Such samples (whose outward nudge is inside the shape on both
    // sides) are left out of the fit.
    const TriangleBvh bvh(V, F);
    const double eps = 2e-3 * bounding_box_diagonal(V);
    std::vector<char> buried(static_cast<size_t>(all.size()), 0);
    parallel_blocks(all.size(), 256, [&](long begin, long end) {
      for (long s = begin; s < end; ++s) {
        const Eigen::Vector3d p = all.P.row(s).transpose(), n = all.N.row(s).transpose();
        buried[static_cast<size_t>(s)] = bvh.inside(p + eps * n) && bvh.inside(p - eps * n);
      }
    });
    std::vector<int> keep;
    for (int s = 0; s < all.size(); ++s)
      if (!buried[static_cast<size_t>(s)]) keep.push_back(s);
    if (keep.size() >= 4 * static_cast<size_t>(Q_.rows())) all = select_samples(all, keep);
  }
  colloc_ = select_samples(all, farthest_point_sampling(all.P, opt.num_collocation, 0));
  F_ = F;
  if (colloc_.size() < Q_.rows())
    return Status::error(StatusCode::InvalidMesh,
                         "the surface is too small for the MFS fit: " + std::to_string(colloc_.size()) +
                             " collocation points for " + std::to_string(Q_.rows()) + " singularity points");
  if (!progress.update("svd", 0.5)) return cancelled_status("svd");
  const Eigen::MatrixXd As = mfs_kernel(colloc_.P, Q_);  // N_c by N_a, Eq. 3
  // Sec. 7.1: As = U S Vᵀ, As⁺ = V S⁻¹ Uᵀ with small singular values dropped (truncated SVD):
  // plain inversion of the tiny ones amplifies noise into huge, oscillating coefficients.
  Eigen::BDCSVD<Eigen::MatrixXd> svd(As, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  if (sv.size() == 0 || !(sv[0] > 0) || !std::isfinite(sv[0]))
    return Status::error(StatusCode::NumericalError, "the MFS collocation matrix is zero or not finite");
  condition_ = sv[0] / sv[sv.size() - 1];
  const double cut = opt.svd_truncation * sv[0];
  rank_ = 0;
  while (rank_ < sv.size() && sv[rank_] > cut) ++rank_;
  const Eigen::VectorXd inv = sv.head(rank_).cwiseInverse();
  U_ = svd.matrixU().leftCols(rank_);
  VSinv_ = svd.matrixV().leftCols(rank_) * inv.asDiagonal();
  if (!U_.allFinite() || !VSinv_.allFinite())
    return Status::error(StatusCode::NumericalError, "MFS pseudo-inverse is not finite");
  progress.update("svd", 1);
  return Status::success();
}

Eigen::MatrixXd MfsHarmonicMap::project(const Eigen::MatrixXd& B) const { return transposed_times_n3(U_, B); }

Eigen::MatrixXd MfsHarmonicMap::fit(const Eigen::MatrixXd& V_deformed) const {
  return fit_collocation(colloc_.positions(V_deformed, F_));
}

}  // namespace mm
