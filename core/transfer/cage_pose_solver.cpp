#include "transfer/cage_pose_solver.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "linalg/polar.h"
#include "mesh/mesh.h"
#include "mesh/topology.h"

namespace mm {

namespace cage_pose_detail {

// App. A: R v = M(v) (s, a, b, c)ᵀ for R = [[s,−c,b],[c,s,−a],[−b,a,s]].
Eigen::Matrix<double, 3, 4> similarity_rows(const Eigen::Vector3d& v) {
  Eigen::Matrix<double, 3, 4> M;
  M << v.x(), 0, v.z(), -v.y(),  //
      v.y(), -v.z(), 0, v.x(),   //
      v.z(), v.y(), -v.x(), 0;
  return M;
}

// Per cage vertex: θ = (s, a, b, c) as a linear function of the cage, θ = Σ_k U_k (x_k − x_i).
struct LocalFit {
  std::vector<Eigen::Matrix<double, 4, 3>> U;  // one 4x3 block per neighbour
  Eigen::Vector3d delta;                       // rotated rest Laplacian coordinate δ_i
};

}  // namespace cage_pose_detail

CagePoseResult solve_cage_pose(const CagePoseProblem& problem, const CagePoseOptions& opt,
                               const Progress& progress) {
  using namespace cage_pose_detail;
  CagePoseResult out;
  const int m = static_cast<int>(problem.C.rows());
  const int K1 = static_cast<int>(problem.P.rows());
  if (problem.P.cols() != m || problem.T.rows() != K1 || problem.T.cols() != 3 || m < 4 ||
      static_cast<long>(problem.fixed.size()) != problem.fixed_positions.rows()) {
    out.status = Status::error(StatusCode::InvalidArgument, "cage pose problem: inconsistent sizes");
    return out;
  }
  const auto adj = vertex_adjacency(problem.CF, m);
  for (int i = 0; i < m; ++i)
    if (adj[i].size() < 2) {
      out.status = Status::error(StatusCode::InvalidMesh,
                                 "cage vertex " + std::to_string(i) + " has fewer than two neighbours");
      return out;
    }
  const int n = 3 * m;
  const double diag = bounding_box_diagonal(problem.C);
  std::vector<Eigen::Matrix3d> frame(m, Eigen::Matrix3d::Identity());
  std::vector<Eigen::Vector3d> rest_delta(m);
  for (int i = 0; i < m; ++i) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int k : adj[i]) mean += problem.C.row(k).transpose();
    rest_delta[i] = problem.C.row(i).transpose() - mean / adj[i].size();
  }
  // Unknowns interleaved: x[3j + c].
  const bool has_init = problem.C_init.rows() == m && problem.C_init.cols() == 3;
  const Eigen::MatrixXd& start = has_init ? problem.C_init : problem.C;
  Eigen::VectorXd x(n);
  for (int j = 0; j < m; ++j)
    for (int c = 0; c < 3; ++c) x[3 * j + c] = start(j, c);
  if (has_init) {
    // Initial frames: rotation of the least-squares linear map from rest to initial one-ring edges.
    for (int i = 0; i < m; ++i) {
      Eigen::Matrix3d M = Eigen::Matrix3d::Zero(), E = Eigen::Matrix3d::Zero();
      for (int k : adj[i]) {
        const Eigen::Vector3d e0 = (problem.C.row(k) - problem.C.row(i)).transpose();
        const Eigen::Vector3d e1 = (start.row(k) - start.row(i)).transpose();
        M += e1 * e0.transpose();
        E += e0 * e0.transpose();
      }
      frame[i] = polar_decomposition(M).R;
    }
  }
  double frame_step = 1.0;  // fraction of each fitted rotation applied to the frames
  // Dense part: b_lf = vec(Pᵀ T); (P⊗I)ᵀ(P⊗I) x = vec(Pᵀ P X).
  const Eigen::MatrixXd PtT = problem.P.transpose() * problem.T;
  auto apply_lf = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y) {
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> V(v.data(), m, 3);
    const Eigen::MatrixXd PV = problem.P * V;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> Y(y.data(), m, 3);
    Y.noalias() += problem.P.transpose() * PV;
  };
  const double w1 = std::sqrt(opt.lambda1), w2 = std::sqrt(opt.lambda2);
  std::vector<LocalFit> fit(m);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> pre;
  std::vector<int> pattern_outer, pattern_inner;

  for (int it = 0; it < opt.max_iterations; ++it) {
    if (!progress.update("optimisation", double(it) / opt.max_iterations)) {
      out.status = cancelled_status("optimisation");
      return out;
    }
    // Local fits in the current frames (App. A with rotated rest one-rings).
    std::vector<Eigen::Triplet<double>> jt;
    jt.reserve(static_cast<size_t>(m) * 60);
    Eigen::VectorXd r0 = Eigen::VectorXd::Zero(4 * m);
    for (int i = 0; i < m; ++i) {
      const int ni = static_cast<int>(adj[i].size());
      Eigen::MatrixXd A(3 * ni, 4);
      for (int q = 0; q < ni; ++q) {
        const Eigen::Vector3d e = frame[i] * (problem.C.row(adj[i][q]) - problem.C.row(i)).transpose();
        A.block<3, 4>(3 * q, 0) = similarity_rows(e);
      }
      const Eigen::Matrix4d AtA = A.transpose() * A;
      const Eigen::MatrixXd U = AtA.ldlt().solve(A.transpose());  // 4 by 3 ni
      fit[i].U.resize(ni);
      for (int q = 0; q < ni; ++q) fit[i].U[q] = U.block<4, 3>(0, 3 * q);
      fit[i].delta = frame[i] * rest_delta[i];
      // E_LC rows (3): M(δ) Σ_k U_k (x_k − x_i) − (x_i − mean_k x_k).
      const Eigen::Matrix<double, 3, 4> Md = similarity_rows(fit[i].delta);
      Eigen::Matrix3d self = Eigen::Matrix3d::Zero();
      for (int q = 0; q < ni; ++q) {
        const Eigen::Matrix3d Bk = Md * fit[i].U[q] + Eigen::Matrix3d::Identity() / ni;
        self -= Md * fit[i].U[q];
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            if (Bk(r, c) != 0) jt.emplace_back(3 * i + r, 3 * adj[i][q] + c, w1 * Bk(r, c));
        // E_SF row: s = Σ_k U_k[0] (x_k − x_i).
        for (int c = 0; c < 3; ++c)
          if (fit[i].U[q](0, c) != 0) jt.emplace_back(3 * m + i, 3 * adj[i][q] + c, w2 * fit[i].U[q](0, c));
      }
      self -= Eigen::Matrix3d::Identity();
      Eigen::RowVector3d sself = Eigen::RowVector3d::Zero();
      for (int q = 0; q < ni; ++q) sself -= fit[i].U[q].row(0);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) jt.emplace_back(3 * i + r, 3 * i + c, w1 * self(r, c));
      for (int c = 0; c < 3; ++c) jt.emplace_back(3 * m + i, 3 * i + c, w2 * sself[c]);
      r0[3 * m + i] = w2;  // s_i − 1 = 0
    }
    Eigen::SparseMatrix<double> J(4 * m, n);
    J.setFromTriplets(jt.begin(), jt.end());
    Eigen::SparseMatrix<double> S = J.transpose() * J;  // same pattern every iteration (see below)
    Eigen::VectorXd b = J.transpose() * r0;
    for (int j = 0; j < m; ++j)
      for (int c = 0; c < 3; ++c) b[3 * j + c] += PtT(j, c);
    // Fixed cage vertices: a stiff spring (hierarchical transfer of parts).
    const double mean_diag = S.diagonal().sum() / n + problem.P.squaredNorm() / n;
    const double w_fix = 1e8 * std::max(mean_diag, 1e-300);
    for (size_t f = 0; f < problem.fixed.size(); ++f)
      for (int c = 0; c < 3; ++c) {
        const int d = 3 * problem.fixed[f] + c;
        S.coeffRef(d, d) += w_fix;
        b[d] += w_fix * problem.fixed_positions(f, c);
      }
    // Preconditioner: S + εI (S alone is singular: translations and rotations cost nothing).
    Eigen::SparseMatrix<double> Sreg = S;
    const double eps = 1e-9 * std::max(mean_diag, 1e-300);
    for (int d = 0; d < n; ++d) Sreg.coeffRef(d, d) += eps;
    // The pattern of S (the cage's two-ring) rarely changes between iterations: the ordering and
    // symbolic analysis are redone only when it does.
    const bool same_pattern = it > 0 && static_cast<size_t>(Sreg.nonZeros()) == pattern_inner.size() &&
                              std::equal(Sreg.outerIndexPtr(), Sreg.outerIndexPtr() + n + 1, pattern_outer.begin()) &&
                              std::equal(Sreg.innerIndexPtr(), Sreg.innerIndexPtr() + Sreg.nonZeros(), pattern_inner.begin());
    if (!same_pattern) {
      pre.analyzePattern(Sreg);
      pattern_outer.assign(Sreg.outerIndexPtr(), Sreg.outerIndexPtr() + n + 1);
      pattern_inner.assign(Sreg.innerIndexPtr(), Sreg.innerIndexPtr() + Sreg.nonZeros());
    }
    pre.factorize(Sreg);
    if (pre.info() != Eigen::Success) {
      out.status = Status::error(StatusCode::FactorizationFailed, "cage pose: factorization of the cage system failed");
      return out;
    }
    auto apply_H = [&](const Eigen::VectorXd& v) {
      Eigen::VectorXd y = S * v;
      apply_lf(v, y);
      return y;
    };
    // PCG, warm-started at the current cage.
    Eigen::VectorXd xn = x;
    Eigen::VectorXd r = b - apply_H(xn);
    const double bnorm = std::max(b.norm(), 1e-300);
    Eigen::VectorXd z = pre.solve(r);
    Eigen::VectorXd d = z;
    double rz = r.dot(z);
    for (int k = 0; k < opt.max_cg_iterations && r.norm() > opt.cg_tolerance * bnorm; ++k) {
      const Eigen::VectorXd Hd = apply_H(d);
      const double dHd = d.dot(Hd);
      if (!(dHd > 0)) break;
      const double alpha = rz / dHd;
      xn += alpha * d;
      r -= alpha * Hd;
      z = pre.solve(r);
      const double rz_new = r.dot(z);
      d = z + (rz_new / rz) * d;
      rz = rz_new;
      ++out.cg_iterations;
    }
    if (!xn.allFinite()) {
      out.status = Status::error(StatusCode::NumericalError, "cage pose: the linear solve produced non-finite values");
      return out;
    }
    // Energies of this linearization at the solution.
    {
      const Eigen::VectorXd res = J * xn - r0;
      out.energy_lc = res.head(3 * m).squaredNorm() / std::max(opt.lambda1, 1e-300);
      out.energy_sf = res.tail(m).squaredNorm() / std::max(opt.lambda2, 1e-300);
      const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> X(xn.data(), m, 3);
      out.energy_lf = (problem.P * X - problem.T).squaredNorm();
      out.energy.push_back(out.energy_lf + opt.lambda1 * out.energy_lc + opt.lambda2 * out.energy_sf);
    }
    // Re-linearize: accumulate each vertex's fitted rotation into its frame.
    double move = 0;
    for (int j = 0; j < m; ++j)
      move = std::max(move, (xn.segment<3>(3 * j) - x.segment<3>(3 * j)).norm());
    for (int i = 0; i < m; ++i) {
      Eigen::Vector4d theta = Eigen::Vector4d::Zero();
      for (size_t q = 0; q < adj[i].size(); ++q)
        theta += fit[i].U[q] * (xn.segment<3>(3 * adj[i][q]) - xn.segment<3>(3 * i));
      Eigen::Matrix3d Ti;
      Ti << theta[0], -theta[3], theta[2], theta[3], theta[0], -theta[1], -theta[2], theta[1], theta[0];
      Eigen::Matrix3d Ri = polar_decomposition(Ti).R;
      if (frame_step < 1.0) {
        Eigen::AngleAxisd aa(Ri);
        Ri = Eigen::AngleAxisd(frame_step * aa.angle(), aa.axis()).toRotationMatrix();
      }
      frame[i] = Ri * frame[i];
    }
    if (out.energy.size() >= 2 && out.energy.back() > out.energy[out.energy.size() - 2]) frame_step *= 0.5;
    x = xn;
    out.iterations = it + 1;
    out.max_move.push_back(move / std::max(diag, 1e-300));
    if (move <= opt.tolerance * diag) {
      out.converged = true;
      break;
    }
  }
  out.C.resize(m, 3);
  for (int j = 0; j < m; ++j)
    for (int c = 0; c < 3; ++c) out.C(j, c) = x[3 * j + c];
  progress.update("optimisation", 1.0);
  return out;
}

CagePoseEnergy cage_pose_energy(const CagePoseProblem& problem, const Eigen::MatrixXd& X, const CagePoseOptions& opt) {
  CagePoseEnergy e;
  const int m = static_cast<int>(problem.C.rows());
  if (X.rows() != m || X.cols() != 3 || problem.P.cols() != m) return e;
  const auto adj = vertex_adjacency(problem.CF, m);
  e.lf = (problem.P * X - problem.T).squaredNorm();
  for (int i = 0; i < m; ++i) {
    if (adj[i].empty()) continue;
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    double n0 = 0;
    Eigen::Vector3d mean0 = Eigen::Vector3d::Zero(), mean1 = Eigen::Vector3d::Zero();
    for (int k : adj[i]) {
      const Eigen::Vector3d e0 = (problem.C.row(k) - problem.C.row(i)).transpose();
      const Eigen::Vector3d e1 = (X.row(k) - X.row(i)).transpose();
      M += e1 * e0.transpose();
      n0 += e0.squaredNorm();
      mean0 += problem.C.row(k).transpose();
      mean1 += X.row(k).transpose();
    }
    const Eigen::Matrix3d R = polar_decomposition(M).R;
    const double s = (R.transpose() * M).trace() / std::max(n0, 1e-300);
    const Eigen::Vector3d d0 = problem.C.row(i).transpose() - mean0 / adj[i].size();
    const Eigen::Vector3d d1 = X.row(i).transpose() - mean1 / adj[i].size();
    e.lc += (s * R * d0 - d1).squaredNorm();
    e.sf += (s - 1) * (s - 1);
  }
  e.total = e.lf + opt.lambda1 * e.lc + opt.lambda2 * e.sf;
  return e;
}

}  // namespace mm
