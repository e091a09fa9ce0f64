#include "edit/implicit_gradients.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "mesh/topology.h"
#include "operators/operators.h"

namespace mm {

namespace edit_detail {

// Eigenvalues (ascending) and eigenvectors of the 3x3 spread Σ (p − c)(p − c)ᵀ of a point set.
// computeDirect is closed-form (fast); its absolute error ~1e-16·λmax is far below what the
// 2e5 threshold needs (λmin/λmax ≥ 5e-6).
struct EditSpread3 {
  Eigen::Vector3d values;
  Eigen::Matrix3d vectors;
};

EditSpread3 edit_spread_of(const Eigen::Matrix3d& S) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(S);
  return {es.eigenvalues(), es.eigenvectors()};
}

double edit_condition_of(const Eigen::Vector3d& ascending) {
  if (!(ascending[0] > 0) || !std::isfinite(ascending[2])) return std::numeric_limits<double>::infinity();
  return ascending[2] / ascending[0];
}

// V_i V_iᵀ of Eq. 3/4: columns are the stencil points (center first, then `nbrs`) minus the
// centroid of the neighbours (v_{i0} in the paper).
Eigen::Matrix3d edit_gram_of(const Eigen::MatrixXd& P, int center, const std::vector<int>& nbrs) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int j : nbrs) c += P.row(j).transpose();
  c /= static_cast<double>(nbrs.size());
  Eigen::Vector3d d = P.row(center).transpose() - c;
  Eigen::Matrix3d G = d * d.transpose();
  for (int j : nbrs) {
    d = P.row(j).transpose() - c;
    G.noalias() += d * d.transpose();
  }
  return G;
}

Eigen::Matrix3d edit_neighbour_spread(const Eigen::MatrixXd& P, const std::vector<int>& nbrs) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int j : nbrs) c += P.row(j).transpose();
  c /= static_cast<double>(nbrs.size());
  Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
  for (int j : nbrs) {
    const Eigen::Vector3d d = P.row(j).transpose() - c;
    G.noalias() += d * d.transpose();
  }
  return G;
}

}  // namespace edit_detail

Eigen::Matrix3d ImplicitGradients::gradient(int c, const Eigen::MatrixXd& X) const {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (int e = offsets[c]; e < offsets[c + 1]; ++e)
    M.noalias() += X.row(stencil[e]).transpose() * weights.row(e);
  return M;
}

ImplicitGradients implicit_gradients(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                     const std::vector<std::vector<int>>& adjacency,
                                     std::vector<int> centers, const ImplicitGradientOptions& opt) {
  using namespace edit_detail;
  ImplicitGradients out;
  std::sort(centers.begin(), centers.end());
  centers.erase(std::unique(centers.begin(), centers.end()), centers.end());
  out.centers = centers;
  out.V_displaced = V;
  Eigen::MatrixXd& P = out.V_displaced;
  const int n = static_cast<int>(V.rows());
  const double thr = opt.condition_threshold;

  const std::vector<char> boundary = boundary_vertices(F, adjacency);
  const Eigen::MatrixXd N = vertex_normals(V, F);

  // Stencil neighbours per center (1-ring, or 2-ring when widened).
  std::vector<std::vector<int>> nbrs(centers.size());
  std::vector<char> is_widened(centers.size(), 0), was_degenerate(centers.size(), 0);
  for (size_t c = 0; c < centers.size(); ++c) {
    const int i = centers[c];
    if (adjacency[i].empty()) {
      out.status = Status::error(StatusCode::InvalidMesh,
                                 "vertex " + std::to_string(i) + " has no neighbours (isolated vertex in the edited region)");
      return out;
    }
    nbrs[c] = adjacency[i];
  }
  auto widen = [&](size_t c) {
    std::vector<int> ring = k_ring(adjacency, centers[c], 2);
    ring.erase(std::remove(ring.begin(), ring.end(), centers[c]), ring.end());
    nbrs[c] = ring;
    is_widened[c] = 1;
  };

  std::vector<char> displaced(n, 0);
  // Eq. 8: v' = v + s_disp · mean_j |v − v_j| · n. The direction is the vertex normal unless it
  // (nearly) lies in the stencil's plane, where the plane normal oriented like it is used instead.
  auto displace = [&](int v, const Eigen::Vector3d& plane_normal) {
    double mean_edge = 0;
    for (int j : adjacency[v]) mean_edge += (V.row(v) - V.row(j)).norm();
    mean_edge /= static_cast<double>(adjacency[v].size());
    Eigen::Vector3d dir = N.row(v).transpose();
    if (dir.squaredNorm() == 0 || std::abs(dir.dot(plane_normal)) < 0.5)
      dir = dir.dot(plane_normal) < 0 ? Eigen::Vector3d(-plane_normal) : plane_normal;
    P.row(v) = V.row(v) + opt.displacement_scale * mean_edge * dir.transpose();
    displaced[v] = 1;
  };

  // The paper traverses the vertex list once, testing each vertex against the positions
  // displaced so far (a displaced vertex usually also regularises its neighbours). We repeat
  // the traversal (at most 3 times) until nothing changes, so a vertex that an earlier
  // displacement did not fix gets another chance. A center that passed the test is not tested
  // again unless a vertex of its stencil moved since (the same positions give the same spread);
  // its spread is kept for the weights below.
  std::vector<long> moved_at(n, -1);  // per vertex: the step of its last displacement
  std::vector<long> tested_at(centers.size(), -1);
  std::vector<char> passed(centers.size(), 0);
  std::vector<Eigen::Vector3d> spread(centers.size());
  long step = 0;
  auto moved_since = [&](size_t c, long t) {
    if (moved_at[centers[c]] >= t) return true;
    for (int j : nbrs[c])
      if (moved_at[j] >= t) return true;
    return false;
  };
  auto test = [&](size_t c, EditSpread3* s) {
    *s = edit_spread_of(edit_gram_of(P, centers[c], nbrs[c]));
    tested_at[c] = step;
    spread[c] = s->values;
    passed[c] = edit_condition_of(s->values) <= thr;
    return passed[c] != 0;
  };
  auto displace_at = [&](int v, const Eigen::Vector3d& plane_normal) {
    displace(v, plane_normal);
    moved_at[v] = ++step;
  };
  for (int pass = 0; pass < 3; ++pass) {
    bool changed = false;
    for (size_t c = 0; c < centers.size(); ++c) {
      const int i = centers[c];
      if (pass > 0 && passed[c] && !moved_since(c, tested_at[c] + 1)) continue;
      EditSpread3 s;
      if (test(c, &s)) continue;
      if (pass == 0) was_degenerate[c] = 1;
      if (adjacency[i].size() < 3 && !is_widened[c]) {
        widen(c);
        changed = true;
        if (test(c, &s)) continue;
      }
      const EditSpread3 ns = edit_spread_of(edit_neighbour_spread(P, nbrs[c]));
      const bool collinear = !(ns.values[1] > ns.values[2] / thr);
      if (collinear) {
        // Displacing i cannot help (only two directions either way): move a neighbouring
        // interior vertex off the line instead (Sec. 3.3).
        int pick = -1;
        for (int j : adjacency[i])
          if (!boundary[j] && !displaced[j]) {
            pick = j;
            break;
          }
        if (pick >= 0) {
          displace_at(pick, N.row(pick).transpose().squaredNorm() > 0 ? Eigen::Vector3d(N.row(pick).transpose())
                                                                      : Eigen::Vector3d(s.vectors.col(0)));
          changed = true;
        } else if (!is_widened[c]) {
          widen(c);
          tested_at[c] = -1;  // its stencil changed: the kept spread is stale
          changed = true;
        }
      } else if (!displaced[i]) {
        displace_at(i, s.vectors.col(0));
        changed = true;
      }
    }
    if (!changed) break;
  }

  // Weights of Eq. 4 on the displaced rest mesh: with P_i = V_iᵀ(V_i V_iᵀ)⁻¹ (rows p_k), the
  // centering by the neighbour centroid gives w_center = p_0 and w_j = p_j − (Σ_k p_k)/|N|.
  out.offsets.assign(1, 0);
  size_t entries = 0;
  for (const auto& list : nbrs) entries += list.size() + 1;
  out.stencil.reserve(entries);
  out.offsets.reserve(centers.size() + 1);
  std::vector<Eigen::Vector3d> w;
  w.reserve(entries);
  for (size_t c = 0; c < centers.size(); ++c) {
    const int i = centers[c];
    const Eigen::Matrix3d G = edit_gram_of(P, i, nbrs[c]);
    const bool fresh = tested_at[c] >= 0 && !moved_since(c, tested_at[c] + 1);
    const double cond = edit_condition_of(fresh ? spread[c] : edit_spread_of(G).values);
    if (!(cond <= 1e12)) {
      out.status = Status::error(StatusCode::InvalidMesh,
                                 "the neighbourhood of vertex " + std::to_string(i) +
                                     " is degenerate even after displacement (all its neighbours coincide or the "
                                     "region is a lone triangle fan); remove it from the region of interest");
      return out;
    }
    out.max_condition = std::max(out.max_condition, cond);
    const Eigen::Matrix3d Ginv = G.inverse();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int j : nbrs[c]) centroid += P.row(j).transpose();
    centroid /= static_cast<double>(nbrs[c].size());
    const Eigen::Vector3d p0 = Ginv * (P.row(i).transpose() - centroid);
    Eigen::Vector3d sum = p0;
    out.stencil.push_back(i);
    w.push_back(p0);
    const size_t first = w.size();
    for (int j : nbrs[c]) {
      w.push_back(Ginv * (P.row(j).transpose() - centroid));
      sum += w.back();
      out.stencil.push_back(j);
    }
    const Eigen::Vector3d shift = sum / static_cast<double>(nbrs[c].size());
    for (size_t k = first; k < w.size(); ++k) w[k] -= shift;
    out.offsets.push_back(static_cast<int>(out.stencil.size()));
    if (was_degenerate[c]) out.degenerate.push_back(i);
    if (is_widened[c]) out.widened.push_back(i);
  }
  out.weights.resize(static_cast<Eigen::Index>(w.size()), 3);
  for (size_t e = 0; e < w.size(); ++e) out.weights.row(static_cast<Eigen::Index>(e)) = w[e].transpose();
  for (int v = 0; v < n; ++v)
    if (displaced[v]) out.displaced.push_back(v);
  return out;
}

}  // namespace mm
