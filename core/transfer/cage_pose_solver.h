// The pose-transfer deformation of paper 000 in cage coordinates (Sec. 4.2, Eq. 8, 10–12,
// App. A/B): find the deformed cage C̃ minimising
//   E = ‖P C̃ − T‖²_F                                (E_LF^M, Eq. 8)
//     + λ₁ Σ_i ‖R_i(C̃) δ_i − δ̃_i(C̃)‖²               (E_LC^C, Eq. 10)
//     + λ₂ Σ_i (s_i(C̃) − 1)²                          (E_SF^C, Eq. 11)
// where P = Φ̂_Kᵀ A Ψ ((K+1) by #C: the source's low-frequency coupled basis projected through
// the mean-value coordinates Ψ), T the reference's low-frequency coefficients ((K+1) by 3),
// δ_i the cage's uniform Laplacian coordinates (c_i − mean of neighbours; the cage is coarse
// and irregular, where cotangent weights go negative), and R_i = s_i(I + [w_i]×) Sorkine's
// linearized similarity of cage vertex i fitted to its one-ring (App. A, Eq. 13), which is
// linear in C̃, so every term is a linear least-squares residual (App. B).
//
// Reading of App. A: the similarity is fitted to the edge vectors c_k − c_i (k ∈ N(i)), not to
// absolute positions as printed; absolute positions make R_i absorb the global translation.
//
// Re-linearization: a linearized rotation is only exact for small angles, so after each solve
// every vertex's fitted similarity is split by polar decomposition, its rotation is accumulated
// into the vertex frame, and the next solve fits the remaining (small) similarity to the
// rotated rest one-ring and rotated δ_i. Iterations stop when the largest cage-vertex move is
// below tolerance × cage bbox diagonal (paper 000 reports 4–20 iterations).
//
// Linear solve: the normal matrix is a sparse part S (E_LC, E_SF; its null space holds the
// translations and infinitesimal rotations) plus the dense rank-3(K+1) part (P⊗I)ᵀ(P⊗I).
// Preconditioned conjugate gradients with a sparse LDLᵀ of S + εI as preconditioner converge
// in about 3(K+1) + few steps (the preconditioned matrix is identity plus low rank),
// warm-started at the current cage.
//
// Starting point: the re-linearization is a local method. Callers may pass a starting cage (e.g.
// a coefficient-swap result fitted in the cage subspace); pose_transfer starts from the rest cage.
// On cat-01/lion-01/cat-05 starts from the ground truth fitted in the cage, from the Kovnatsky
// result, or a λ continuation all return to the rest-start minimum (cage_pose_energy below; the
// crouched cat-01 legs are what Eq. 12 prefers, docs/transfer.md); on cat-07 a continuation from
// λ = 0.5 finds a lower energy with a worse pose, so multi-start by energy is not used.
//
// Oscillation: the linearized scale s = scale·cos(residual angle) couples rotation and scale, so
// the frame update can overshoot into a 2-cycle; when the energy rises the frame update is
// halved (rotation vector scaled) for the following iterations.
//
// Works on any cage and any P, so it can be called on parts (hierarchical transfer): cage
// vertices listed in `fixed` keep their given positions (paper 000 Sec. 5 fixes cage vertices
// far from the part being transferred).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

struct CagePoseOptions {
  double lambda1 = 0.05;      // λ₁: weight of the cage Laplacian-coordinate term (Eq. 12)
  double lambda2 = 0.05;      // λ₂: weight of the scale penalty (Eq. 12)
  int max_iterations = 50;    // re-linearizations; paper 000 reports 4–20, we measured 15–50 on
                              // the cat/lion/horse→camel pairs with 450-vertex cages
  double tolerance = 1e-4;    // stop when max cage-vertex move < tolerance × cage bbox diagonal
  int max_cg_iterations = 400; // inner PCG steps per solve
  double cg_tolerance = 1e-13; // inner PCG relative residual
};

struct CagePoseProblem {
  Eigen::MatrixXd C;            // #C by 3 rest cage
  Eigen::MatrixXi CF;           // cage triangles (only their edges are used)
  Eigen::MatrixXd P;            // (K+1) by #C projection of the cage coordinates (see header)
  Eigen::MatrixXd T;            // (K+1) by 3 target coefficients
  Eigen::MatrixXd C_init;       // optional #C by 3 starting cage (empty = C); the vertex frames
                                // start at the rotations fitted from C to C_init
  std::vector<int> fixed;       // optional cage vertices held at `fixed_positions`
  Eigen::MatrixXd fixed_positions; // #fixed by 3
};

struct CagePoseResult {
  Status status;                 // NumericalError when a solve is not finite, Cancelled
  Eigen::MatrixXd C;             // #C by 3 deformed cage C̃
  int iterations = 0;            // re-linearizations performed
  bool converged = false;        // the move fell below tolerance within max_iterations
  std::vector<double> energy;    // E after each iteration (E_LF + λ₁E_LC + λ₂E_SF, rotated frames)
  std::vector<double> max_move;  // largest cage-vertex move of each iteration (cage-diagonal units)
  double energy_lf = 0, energy_lc = 0, energy_sf = 0; // final terms (unweighted)
  int cg_iterations = 0;         // total inner PCG steps
};

CagePoseResult solve_cage_pose(const CagePoseProblem& problem, const CagePoseOptions& opt = {},
                               const Progress& progress = {});

// The (non-linearized) Eq. 12 energy of a cage C̃ (#C by 3) for `problem`: R_i and s_i are the
// exact least-squares similarity (rotation and scale, Procrustes) from the rest one-ring edges of
// cage vertex i to its deformed ones. Near a converged re-linearization it agrees with the last
// entry of CagePoseResult::energy (there the residual rotations are small). Used to compare
// solutions reached from different starting cages. Terms are unweighted; total is weighted.
struct CagePoseEnergy {
  double lf = 0, lc = 0, sf = 0, total = 0;
};
CagePoseEnergy cage_pose_energy(const CagePoseProblem& problem, const Eigen::MatrixXd& C_deformed,
                                const CagePoseOptions& opt = {});

}  // namespace mm
