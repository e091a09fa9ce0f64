#include "retarget/bone_blend.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "retarget/nonrigid_icp.h"

namespace mm {

std::pair<int, double> BoneBlend::dominant(int i) const {
  std::pair<int, double> best{-1, 0.0};
  for (int k = ptr[i]; k < ptr[i + 1]; ++k)
    if (w[k] > best.second) best = {bone[k], w[k]};
  return best;
}

BoneBlend bone_blend(const Eigen::MatrixXd& P, const Eigen::MatrixXd& J, const std::vector<std::pair<int, int>>& bones,
                     double band) {
  BoneBlend out;
  const int n = static_cast<int>(P.rows()), nb = static_cast<int>(bones.size());
  out.ptr.reserve(n + 1);
  std::vector<std::pair<double, int>> d(nb);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = P.row(i).transpose();
    double dmin = std::numeric_limits<double>::infinity();
    int valid = 0;
    for (int b = 0; b < nb; ++b) {
      const Eigen::Vector3d a = J.row(bones[b].second).transpose(), c = J.row(bones[b].first).transpose();
      const Eigen::Vector3d ab = c - a;
      const double L2 = ab.squaredNorm();
      if (!(L2 > 0)) {
        d[b] = {std::numeric_limits<double>::infinity(), b};
        continue;
      }
      const double s = std::clamp((x - a).dot(ab) / L2, 0.0, 1.0);
      d[b] = {(x - a - s * ab).norm(), b};
      dmin = std::min(dmin, d[b].first);
      ++valid;
    }
    if (valid > 0) {
      std::sort(d.begin(), d.end());
      const size_t first = out.bone.size();
      const double on_bone = 1e-12 * (1.0 + x.norm());
      if (dmin <= on_bone) {
        for (int k = 0; k < std::min(nb, BoneBlend::kMaxBones) && d[k].first <= on_bone; ++k) {
          out.bone.push_back(d[k].second);
          out.w.push_back(1.0);
        }
      } else {
        // Raw weights of the bones in the band, largest first; beyond kMaxBones the next raw
        // weight is subtracted from the kept ones, so that two bones trading places at the cut
        // do not make the weights jump.
        const double floor = std::pow(band * dmin, -4.0);
        std::vector<double> raw;
        for (int k = 0; k < nb && d[k].first < band * dmin; ++k) raw.push_back(std::pow(d[k].first, -4.0) - floor);
        const double cut = raw.size() > BoneBlend::kMaxBones ? raw[BoneBlend::kMaxBones] : 0.0;
        for (size_t k = 0; k < std::min<size_t>(raw.size(), BoneBlend::kMaxBones); ++k)
          if (raw[k] - cut > 0) {
            out.bone.push_back(d[k].second);
            out.w.push_back(raw[k] - cut);
          }
      }
      double sum = 0;
      for (size_t k = first; k < out.w.size(); ++k) sum += out.w[k];
      for (size_t k = first; k < out.w.size(); ++k) out.w[k] /= sum;
    }
    out.ptr.push_back(static_cast<int>(out.bone.size()));
  }
  return out;
}

Eigen::MatrixXd apply_bone_motions(const BoneBlend& blend, const Eigen::MatrixXd& P, const BoneMotions& m) {
  Eigen::MatrixXd Y = P;
  for (int i = 0; i < blend.rows(); ++i) {
    if (blend.ptr[i] == blend.ptr[i + 1]) continue;
    const Eigen::Vector3d x = P.row(i).transpose();
    Eigen::Vector3d y = Eigen::Vector3d::Zero();
    for (int k = blend.ptr[i]; k < blend.ptr[i + 1]; ++k) {
      const int b = blend.bone[k];
      y += blend.w[k] * (m.R[b] * x + m.t.row(b).transpose());
    }
    Y.row(i) = y.transpose();
  }
  return Y;
}

BoneBlend learn_bone_weights(const Eigen::MatrixXd& X, const std::vector<Eigen::MatrixXd>& Y,
                             const std::vector<BoneMotions>& M, const BoneBlend& candidates) {
  BoneBlend out;
  const int nf = static_cast<int>(std::min(Y.size(), M.size()));
  for (int i = 0; i < candidates.rows(); ++i) {
    const int b0 = candidates.ptr[i], k = candidates.ptr[i + 1] - b0;
    if (k <= 1 || nf == 0) {
      for (int a = 0; a < k; ++a) out.bone.push_back(candidates.bone[b0 + a]), out.w.push_back(1.0);
      out.ptr.push_back(static_cast<int>(out.bone.size()));
      continue;
    }
    // Columns: each candidate bone's prediction of the point over the frames.
    Eigen::MatrixXd A(3 * nf, k);
    Eigen::VectorXd y(3 * nf), prior(k);
    const Eigen::Vector3d x = X.row(i).transpose();
    for (int f = 0; f < nf; ++f) {
      y.segment<3>(3 * f) = Y[f].row(i).transpose();
      for (int a = 0; a < k; ++a) {
        const int b = candidates.bone[b0 + a];
        A.block<3, 1>(3 * f, a) = M[f].R[b] * x + M[f].t.row(b).transpose();
      }
    }
    for (int a = 0; a < k; ++a) prior[a] = candidates.w[b0 + a];
    const Eigen::MatrixXd AtA = A.transpose() * A;
    const Eigen::VectorXd Aty = A.transpose() * y;
    // The pull towards the prior grows as the prior weight vanishes (μ / prior), so a bone at
    // the edge of the candidates gets no weight it did not have: the weights stay continuous in
    // the point. The exact minimiser on the simplex: every support subset is tried (k ≤ 4).
    const double mu = 1e-4 * std::max(1e-300, AtA.trace() / k);
    Eigen::VectorXd pen(k);
    for (int a = 0; a < k; ++a) pen[a] = mu / std::max(prior[a], 1e-12);
    auto objective = [&](const Eigen::VectorXd& v) {
      double o = v.dot(AtA * v) - 2 * v.dot(Aty);
      for (int a = 0; a < k; ++a) o += pen[a] * (v[a] - prior[a]) * (v[a] - prior[a]);
      return o;
    };
    Eigen::VectorXd w = prior;
    double best = objective(prior);
    for (int mask = 1; mask < (1 << k); ++mask) {
      std::vector<int> free;
      for (int a = 0; a < k; ++a)
        if (mask & (1 << a)) free.push_back(a);
      const int q = static_cast<int>(free.size());
      Eigen::MatrixXd K = Eigen::MatrixXd::Zero(q + 1, q + 1);
      Eigen::VectorXd r(q + 1);
      for (int u = 0; u < q; ++u) {
        for (int v = 0; v < q; ++v) K(u, v) = AtA(free[u], free[v]);
        K(u, u) += pen[free[u]];
        K(u, q) = K(q, u) = 1;
        r[u] = Aty[free[u]] + pen[free[u]] * prior[free[u]];
      }
      r[q] = 1;
      const Eigen::VectorXd sol = K.fullPivLu().solve(r);
      Eigen::VectorXd v = Eigen::VectorXd::Zero(k);
      bool feasible = sol.allFinite();
      for (int u = 0; u < q && feasible; ++u) {
        if (sol[u] < 0) feasible = false;
        v[free[u]] = sol[u];
      }
      if (!feasible) continue;
      const double o = objective(v);
      if (o < best) best = o, w = v;
    }
    if (!w.allFinite() || w.minCoeff() < 0) w = prior;
    for (int a = 0; a < k; ++a)
      if (w[a] > 1e-6) out.bone.push_back(candidates.bone[b0 + a]), out.w.push_back(w[a]);
    double sum = 0;
    for (size_t a = out.ptr.back(); a < out.w.size(); ++a) sum += out.w[a];
    for (size_t a = out.ptr.back(); a < out.w.size(); ++a) out.w[a] /= sum;
    out.ptr.push_back(static_cast<int>(out.bone.size()));
  }
  return out;
}

namespace {

// Distance from x to the segment from J(bone.second) to J(bone.first).
double segment_distance(const Eigen::Vector3d& x, const Eigen::MatrixXd& J, const std::pair<int, int>& bone) {
  const Eigen::Vector3d a = J.row(bone.second).transpose(), ab = J.row(bone.first).transpose() - a;
  const double L2 = ab.squaredNorm();
  const double s = L2 > 0 ? std::clamp((x - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
  return (x - a - s * ab).norm();
}

// Appends a row from (weight, bone) pairs: merged per bone, the kMaxBones largest kept minus the
// next one (no jump at the cut), normalised.
void push_row(std::vector<std::pair<double, int>>& acc, BoneBlend* out) {
  std::sort(acc.begin(), acc.end(), [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
  const double cut = acc.size() > BoneBlend::kMaxBones ? std::max(0.0, acc[BoneBlend::kMaxBones].first) : 0.0;
  if (acc.size() > BoneBlend::kMaxBones) acc.resize(BoneBlend::kMaxBones);
  double sum = 0;
  for (const auto& e : acc) sum += std::max(0.0, e.first - cut);
  for (const auto& e : acc)
    if (e.first - cut > 0 && sum > 0) out->bone.push_back(e.second), out->w.push_back((e.first - cut) / sum);
  out->ptr.push_back(static_cast<int>(out->bone.size()));
}

void accumulate(std::vector<std::pair<double, int>>& acc, int bone, double w) {
  auto it = std::find_if(acc.begin(), acc.end(), [&](const auto& e) { return e.second == bone; });
  if (it == acc.end()) acc.push_back({w, bone});
  else it->first += w;
}

}  // namespace

BoneBlend skin_blend(const Eigen::MatrixXd& P, const Eigen::MatrixXi& index, const Eigen::MatrixXd& weight,
                     const std::vector<std::vector<int>>& drives, const Eigen::MatrixXd& J,
                     const std::vector<std::pair<int, int>>& bones, const BoneBlend& fallback) {
  BoneBlend out;
  std::vector<std::pair<double, int>> acc;
  std::vector<double> raw;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    acc.clear();
    const Eigen::Vector3d x = P.row(i).transpose();
    double kept = 0, total = 0;
    for (Eigen::Index k = 0; k < index.cols(); ++k) {
      const int j = index(i, k);
      const double w = weight(i, k);
      if (!(w > 0)) continue;
      total += w;
      if (j < 0 || j >= static_cast<int>(drives.size()) || drives[j].empty()) continue;
      kept += w;
      // Split among the joint's bones by 1/d⁴ (a tiny floor keeps points on a segment finite).
      const double floor = 1e-9 * (1.0 + x.norm());
      double norm = 0;
      raw.clear();
      for (int b : drives[j]) {
        const double d = std::max(segment_distance(x, J, bones[b]), floor);
        raw.push_back(std::pow(d, -4.0));
        norm += raw.back();
      }
      for (size_t a = 0; a < raw.size(); ++a) accumulate(acc, drives[j][a], w * raw[a] / norm);
    }
    if (!(total > 0) || kept < 0.5 * total) {
      acc.clear();
      if (i < fallback.rows())
        for (int k = fallback.ptr[i]; k < fallback.ptr[i + 1]; ++k) acc.push_back({fallback.w[k], fallback.bone[k]});
    }
    push_row(acc, &out);
  }
  return out;
}

BoneBlend smooth_blend(const BoneBlend& W, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int nb, double sigma) {
  const Eigen::Index n = V.rows();
  if (!(sigma > 0) || n == 0 || F.rows() == 0 || nb <= 0 || W.rows() != n) return W;
  const std::vector<std::pair<int, int>> edges = triangle_edges(F);  // each once
  double ell = 0;
  for (const auto& [a, b] : edges) ell += (V.row(a) - V.row(b)).norm();
  ell /= std::max<size_t>(1, edges.size());
  if (!(ell > 0)) return W;
  const double t = (sigma / ell) * (sigma / ell);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(4 * edges.size() + n);
  for (Eigen::Index i = 0; i < n; ++i) trip.emplace_back(i, i, 1.0);
  for (const auto& [a, b] : edges) {
    trip.emplace_back(a, a, t);
    trip.emplace_back(b, b, t);
    trip.emplace_back(a, b, -t);
    trip.emplace_back(b, a, -t);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  if (solver.info() != Eigen::Success) return W;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, nb);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = W.ptr[i]; k < W.ptr[i + 1]; ++k) D(i, W.bone[k]) += W.w[k];
  const Eigen::MatrixXd S = solver.solve(D);
  if (!S.allFinite()) return W;
  BoneBlend out;
  std::vector<std::pair<double, int>> acc;
  for (Eigen::Index i = 0; i < n; ++i) {
    acc.clear();
    if (W.ptr[i] == W.ptr[i + 1]) {  // a point without bones stays without
      out.ptr.push_back(static_cast<int>(out.bone.size()));
      continue;
    }
    for (int b = 0; b < nb; ++b)
      if (S(i, b) > 1e-12) acc.push_back({S(i, b), b});
    push_row(acc, &out);
  }
  return out;
}

BoneBlend interpolate_blend(const BoneBlend& W, const Eigen::MatrixXi& F, const Eigen::VectorXi& face,
                            const Eigen::MatrixXd& bary, const BoneBlend* fallback) {
  BoneBlend out;
  std::vector<std::pair<double, int>> acc;
  for (Eigen::Index i = 0; i < face.size(); ++i) {
    acc.clear();
    if (face[i] >= 0) {
      for (int c = 0; c < 3; ++c) {
        const int v = F(face[i], c);
        for (int k = W.ptr[v]; k < W.ptr[v + 1]; ++k) accumulate(acc, W.bone[k], bary(i, c) * W.w[k]);
      }
    } else if (fallback) {
      for (int k = fallback->ptr[i]; k < fallback->ptr[i + 1]; ++k) acc.push_back({fallback->w[k], fallback->bone[k]});
    }
    push_row(acc, &out);
  }
  return out;
}

Eigen::MatrixXd articulated_points(const Eigen::MatrixXd& P, const Eigen::MatrixXd& J0, const Eigen::MatrixXd& J1,
                                   const std::vector<std::pair<int, int>>& bones) {
  BoneMotions m;
  m.R.resize(bones.size(), Eigen::Matrix3d::Identity());
  m.t = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(bones.size()), 3);
  for (size_t b = 0; b < bones.size(); ++b) {
    const auto [c, p] = bones[b];
    const Eigen::Vector3d u = (J0.row(c) - J0.row(p)).transpose(), v = (J1.row(c) - J1.row(p)).transpose();
    if (u.norm() > 0 && v.norm() > 0) m.R[b] = Eigen::Quaterniond::FromTwoVectors(u, v).toRotationMatrix();
    m.t.row(b) = J1.row(p) - (m.R[b] * J0.row(p).transpose()).transpose();
  }
  return apply_bone_motions(bone_blend(P, J0, bones), P, m);
}

}  // namespace mm
