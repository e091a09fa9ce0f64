// MFS harmonic map of a calibration shape (paper 002 Sec. 4, 7.1): singularity points on an
// offset surface outside the shape, collocation points on the surface, and the pseudo-inverse
// of the collocation matrix As (Eq. 3), computed once by SVD so that fitting a deformed pose
// is one matrix product, Ws = As⁺ bs (Eq. 13).
//
// Meshless: V/F may be a polygon soup, several parts, non-manifold or open; only closest
// points, inside tests (spatial/triangle_bvh.h) and surface samples are used.
#pragma once

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"
#include "spatial/farthest_point_sampling.h"

namespace mm {

struct SingularityOptions {
  int count = 260;           // N_a singularity points (paper Sec. 4.3: "260 on average")
  double offset = 0.04;      // offset-surface distance, fraction of the bbox diagonal of V
                             // (0.04 gave the lowest self-retargeting errors on CesiumMan and
                             // KayKit among 0.03–0.15; larger offsets cannot reach between legs)
  int offset_levels = 3;     // where the full offset does not fit (gaps between legs, armpits),
                             // offset/2, offset/4, ... are tried, down to this many halvings
  int candidates = 3000;     // surface samples turned into offset candidates before FPS
};

struct SingularityResult {
  Status status;             // InvalidMesh when no candidate lies outside the surface
  Eigen::MatrixXd Q;         // N_a by 3 singularity points (fewer when candidates ran out)
  double min_clearance = 0;  // smallest distance from a singularity to the surface
};

// Offset candidates s ± o·n (both sides: the surface may be open, single-sided or inverted)
// kept when they are outside the shape and at least 0.8·o away from the surface, then
// N_a of them by farthest-point sampling (paper Sec. 4.3 uses a progressive hull; an offset
// sampled this way is what Sec. 2.4 calls "offset points close to the boundary surface").
SingularityResult singularity_points(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                     const SingularityOptions& opt = {});

struct HarmonicMapOptions {
  SingularityOptions singularities;
  int num_collocation = 1500;   // N_c collocation points (FPS over surface samples); N_c ≫ N_a
                                // makes Eq. 3 an over-determined least-squares fit
  double svd_truncation = 1e-9; // singular values of As below this × σ_max are dropped in As⁺
                                // (Sec. 7.1): MFS matrices are ill-conditioned (cond ~1e10 here);
                                // the truncation keeps fitted coefficients bounded while the
                                // collocation residual stays below 1e-4 of the size (tests)
};

class MfsHarmonicMap {
 public:
  // Samples singularity and collocation points on (V, F) and factors As by SVD.
  // Progress stages: "singularities", "collocation", "svd".
  Status build(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const HarmonicMapOptions& opt = {},
               const Progress& progress = {});

  // Ws (N_a by 3) such that K(P) Ws ≈ the collocation points of the deformed surface
  // V_deformed (same vertex layout and F as at build). Eq. 13.
  Eigen::MatrixXd fit(const Eigen::MatrixXd& V_deformed) const;
  // Collocation points (N_c by 3) of a deformed copy of the surface: bs of Eq. 3.
  Eigen::MatrixXd collocation_positions(const Eigen::MatrixXd& V_deformed) const {
    return colloc_.positions(V_deformed, F_);
  }
  // The same from the deformed collocation positions (N_c by 3) directly.
  Eigen::MatrixXd fit_collocation(const Eigen::MatrixXd& B) const { return from_projection(project(B)); }

  // As⁺ = V S⁻¹ Uᵀ is kept factored (rank r ≤ N_a): project(B) = Uᵀ B (r by 3) and
  // Ws = from_projection(Y) = V S⁻¹ Y. Callers that apply a fixed linear map M after the fit
  // precompute M V S⁻¹ (coefficient_map()) and work on the r-dimensional projection; the fit's
  // collocation residual is then ‖B‖² − ‖Uᵀ B‖² (As Ws = U Uᵀ B is an orthogonal projection).
  Eigen::MatrixXd project(const Eigen::MatrixXd& B) const;
  Eigen::MatrixXd from_projection(const Eigen::MatrixXd& Y) const { return VSinv_ * Y; }
  const Eigen::MatrixXd& coefficient_map() const { return VSinv_; }  // N_a by r: V S⁻¹

  const Eigen::MatrixXd& singularities() const { return Q_; }   // N_a by 3
  const SurfaceSamples& collocation() const { return colloc_; }  // N_c samples
  int rank() const { return rank_; }                             // kept singular values
  double condition() const { return condition_; }                // σ_max / σ_min of As
  int num_singularities() const { return static_cast<int>(Q_.rows()); }

 private:
  Eigen::MatrixXd Q_;
  SurfaceSamples colloc_;
  Eigen::MatrixXi F_;
  Eigen::MatrixXd U_;      // N_c by r: U of the truncated SVD of As
  Eigen::MatrixXd VSinv_;  // N_a by r: V S⁻¹
  int rank_ = 0;
  double condition_ = 0;
};

}  // namespace mm
