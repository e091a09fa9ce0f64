#include "merge/transition.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <queue>
#include <string>

#include "linalg/spd_solver.h"
#include "mesh/topology.h"
#include "operators/operators.h"

namespace mm {

namespace {

constexpr double kTwoPi = 6.28318530717958647692;

// One side of the seam parameterized over the unit square: u along the seam (periodic), v across.
struct SideParam {
  std::vector<int> verts;        // region vertices of this side
  std::vector<int> local;        // per merged vertex: index into verts or -1
  std::vector<double> u, v;      // per region vertex
  std::vector<Eigen::Vector3i> tris;  // region triangles (indices into verts)
  // Uniform grid over [0, 2) × [0, 1] of triangle lists (u may be unwrapped up to < 2).
  int gu = 1, gv = 1;
  std::vector<std::vector<int>> cells;
};

// Multi-source Dijkstra over the vertices of one side from the seam loop; u starts as the seam
// vertex's arc-length parameter and is then relaxed harmonically (averaged on the unit circle,
// so that the wrap at u = 0 ≡ 1 needs no special case) with the seam fixed.
SideParam parameterize_side(const Eigen::MatrixXd& V, const std::vector<std::vector<int>>& adj,
                            const std::vector<char>& on_side, const std::vector<int>& seam, double width) {
  const int n = static_cast<int>(V.rows());
  SideParam p;
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<double> label(n, 0.0);
  // Arc-length parameter along the seam.
  std::vector<double> arc(seam.size() + 1, 0.0);
  for (size_t k = 0; k < seam.size(); ++k)
    arc[k + 1] = arc[k] + (V.row(seam[(k + 1) % seam.size()]) - V.row(seam[k])).norm();
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (size_t k = 0; k < seam.size(); ++k) {
    dist[seam[k]] = 0;
    label[seam[k]] = arc.back() > 0 ? arc[k] / arc.back() : 0.0;
    queue.emplace(0.0, seam[k]);
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    for (int w : adj[v]) {
      if (!on_side[w]) continue;
      const double nd = d + (V.row(v) - V.row(w)).norm();
      if (nd < dist[w] && nd < width) {
        dist[w] = nd;
        label[w] = label[v];
        queue.emplace(nd, w);
      }
    }
  }
  p.local.assign(n, -1);
  std::vector<char> is_seam(n, 0);
  for (int s : seam) is_seam[s] = 1;
  for (int v = 0; v < n; ++v)
    if (on_side[v] && dist[v] < width) {
      p.local[v] = static_cast<int>(p.verts.size());
      p.verts.push_back(v);
      p.v.push_back(dist[v] / width);
    }
  std::vector<std::complex<double>> z(p.verts.size());
  for (size_t k = 0; k < p.verts.size(); ++k) z[k] = std::polar(1.0, kTwoPi * label[p.verts[k]]);
  for (int it = 0; it < 30; ++it) {
    std::vector<std::complex<double>> next = z;
    for (size_t k = 0; k < p.verts.size(); ++k) {
      const int v = p.verts[k];
      if (is_seam[v]) continue;
      std::complex<double> sum = 0;
      for (int w : adj[v])
        if (p.local[w] >= 0) sum += z[p.local[w]];
      if (std::abs(sum) > 1e-12) next[k] = sum / std::abs(sum);
    }
    z.swap(next);
  }
  p.u.resize(p.verts.size());
  for (size_t k = 0; k < z.size(); ++k) {
    double a = std::arg(z[k]) / kTwoPi;
    p.u[k] = a < 0 ? a + 1 : a;
  }
  return p;
}

void build_grid(const Eigen::MatrixXi& F, SideParam* p) {
  for (int f = 0; f < F.rows(); ++f) {
    const int a = p->local[F(f, 0)], b = p->local[F(f, 1)], c = p->local[F(f, 2)];
    if (a >= 0 && b >= 0 && c >= 0) p->tris.emplace_back(a, b, c);
  }
  const int m = std::max<int>(1, static_cast<int>(std::sqrt(static_cast<double>(p->tris.size()))));
  p->gu = 2 * m;
  p->gv = std::max(1, m / 2);
  p->cells.assign(static_cast<size_t>(p->gu) * p->gv, {});
  for (size_t t = 0; t < p->tris.size(); ++t) {
    double us[3], vs[3];
    for (int k = 0; k < 3; ++k) {
      us[k] = p->u[p->tris[t][k]];
      vs[k] = p->v[p->tris[t][k]];
    }
    const double lo = std::min({us[0], us[1], us[2]}), hi = std::max({us[0], us[1], us[2]});
    if (hi - lo > 0.5)
      for (double& x : us)
        if (x < 0.5) x += 1;  // straddles the cut: unwrap
    const auto cu = [&](double x) { return std::clamp(static_cast<int>(x / 2.0 * p->gu), 0, p->gu - 1); };
    const auto cv = [&](double x) { return std::clamp(static_cast<int>(x * p->gv), 0, p->gv - 1); };
    for (int i = cu(std::min({us[0], us[1], us[2]})); i <= cu(std::max({us[0], us[1], us[2]})); ++i)
      for (int j = cv(std::min({vs[0], vs[1], vs[2]})); j <= cv(std::max({vs[0], vs[1], vs[2]})); ++j)
        p->cells[static_cast<size_t>(i) * p->gv + j].push_back(static_cast<int>(t));
  }
}

// δ of this side interpolated at (u, v); false when no triangle contains the point.
bool interpolate(const SideParam& p, const Eigen::MatrixXd& delta, double u, double v, Eigen::RowVector3d* out) {
  for (double uu : {u, u + 1.0}) {
    const int i = std::clamp(static_cast<int>(uu / 2.0 * p.gu), 0, p.gu - 1);
    const int j = std::clamp(static_cast<int>(v * p.gv), 0, p.gv - 1);
    for (int t : p.cells[static_cast<size_t>(i) * p.gv + j]) {
      double us[3], vs[3];
      for (int k = 0; k < 3; ++k) {
        us[k] = p.u[p.tris[t][k]];
        vs[k] = p.v[p.tris[t][k]];
      }
      if (std::max({us[0], us[1], us[2]}) - std::min({us[0], us[1], us[2]}) > 0.5)
        for (double& x : us)
          if (x < 0.5) x += 1;
      const double det = (us[1] - us[0]) * (vs[2] - vs[0]) - (us[2] - us[0]) * (vs[1] - vs[0]);
      if (std::abs(det) < 1e-300) continue;
      const double b1 = ((uu - us[0]) * (vs[2] - vs[0]) - (us[2] - us[0]) * (v - vs[0])) / det;
      const double b2 = ((us[1] - us[0]) * (v - vs[0]) - (uu - us[0]) * (vs[1] - vs[0])) / det;
      const double b0 = 1 - b1 - b2;
      const double eps = -1e-9;
      if (b0 >= eps && b1 >= eps && b2 >= eps) {
        *out = b0 * delta.row(p.verts[p.tris[t][0]]) + b1 * delta.row(p.verts[p.tris[t][1]]) +
               b2 * delta.row(p.verts[p.tris[t][2]]);
        return true;
      }
    }
  }
  return false;
}

Eigen::RowVector3d nearest(const SideParam& p, const Eigen::MatrixXd& delta, double u, double v) {
  int best = 0;
  double bd = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < p.verts.size(); ++k) {
    double du = std::abs(p.u[k] - u);
    du = std::min(du, 1 - du);
    const double d = du * du + (p.v[k] - v) * (p.v[k] - v);
    if (d < bd) {
      bd = d;
      best = static_cast<int>(k);
    }
  }
  return delta.row(p.verts[best]);
}

}  // namespace

Status blend_transition(Eigen::MatrixXd* Vp, const Eigen::MatrixXi& F, int first_source,
                        const std::vector<TransitionSeam>& seams, double target_width, double source_width,
                        const Eigen::MatrixXd& H, TransitionReport* report) {
  Eigen::MatrixXd& V = *Vp;
  const int n = static_cast<int>(V.rows());
  if (!(target_width > 0 && source_width > 0) || !std::isfinite(target_width + source_width))
    return Status::error(StatusCode::InvalidArgument, "transition widths must be positive");
  const auto adj = vertex_adjacency(F, n);
  std::vector<char> target_side(n, 0), source_side(n, 0);
  for (int v = 0; v < n; ++v) (v < first_source ? target_side : source_side)[v] = 1;
  if (H.rows() != n || H.cols() != 3) return Status::error(StatusCode::InvalidArgument, "transition: H must be #V by 3");
  const Eigen::MatrixXd& delta = H;
  const Eigen::VectorXd area = mass_diagonal(V, F);
  std::vector<char> in_region(n, 0);
  Eigen::MatrixXd blended = cotan_stiffness(V, F) * V;
  for (const TransitionSeam& seam : seams) {
    if (seam.target_side.size() < 3 || seam.source_side.size() < 3)
      return Status::error(StatusCode::InvalidArgument, "transition: a seam has fewer than 3 vertices per side");
    SideParam pt = parameterize_side(V, adj, target_side, seam.target_side, target_width);
    SideParam ps = parameterize_side(V, adj, source_side, seam.source_side, source_width);
    build_grid(F, &pt);
    build_grid(F, &ps);
    const double total = target_width + source_width;
    auto blend_side = [&](const SideParam& own, const SideParam& other, bool own_is_target) {
      for (size_t k = 0; k < own.verts.size(); ++k) {
        const int v = own.verts[k];
        in_region[v] = 1;
        Eigen::RowVector3d theirs;
        if (!interpolate(other, delta, own.u[k], own.v[k], &theirs)) {
          theirs = nearest(other, delta, own.u[k], own.v[k]);
          if (report) ++report->fallback_lookups;
        }
        const double d_t = own_is_target ? own.v[k] * target_width : 0.0, d_s = own_is_target ? 0.0 : own.v[k] * source_width;
        const double s = own_is_target ? (target_width - d_t) / total : (target_width + d_s) / total;  // source weight
        const Eigen::RowVector3d mine = delta.row(v);
        blended.row(v) = area[v] * (own_is_target ? (1 - s) * mine + s * theirs : (1 - s) * theirs + s * mine);
      }
    };
    blend_side(pt, ps, true);
    blend_side(ps, pt, false);
  }
  // Rebuild the region: unknowns are region vertices whose neighbours are all in the region.
  std::vector<int> unknown_of(n, -1), unknowns;
  const auto loops = boundary_loops(F, n);
  std::vector<char> on_boundary(n, 0);
  for (const auto& l : loops)
    for (int v : l) on_boundary[v] = 1;
  for (int v = 0; v < n; ++v) {
    if (!in_region[v] || on_boundary[v]) continue;
    bool inner = true;
    for (int w : adj[v]) inner = inner && in_region[w];
    if (inner) {
      unknown_of[v] = static_cast<int>(unknowns.size());
      unknowns.push_back(v);
    }
  }
  if (report) report->region_vertices = static_cast<int>(unknowns.size());
  if (unknowns.empty()) return Status::success();
  const SparseMatrix K = cotan_stiffness(V, F);
  std::vector<Eigen::Triplet<double>> t;
  Eigen::MatrixXd rhs(unknowns.size(), 3);
  for (size_t k = 0; k < unknowns.size(); ++k) rhs.row(static_cast<Eigen::Index>(k)) = blended.row(unknowns[k]);
  for (int col = 0; col < K.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(K, col); it; ++it) {
      const int r = static_cast<int>(it.row()), c = static_cast<int>(it.col());
      if (unknown_of[r] < 0) continue;
      if (unknown_of[c] >= 0) {
        if (unknown_of[c] <= unknown_of[r]) t.emplace_back(unknown_of[r], unknown_of[c], it.value());
      } else {
        rhs.row(unknown_of[r]) -= it.value() * V.row(c);
      }
    }
  SparseMatrix A(static_cast<Eigen::Index>(unknowns.size()), static_cast<Eigen::Index>(unknowns.size()));
  A.setFromTriplets(t.begin(), t.end());
  SpdSolver solver;
  if (Status s = solver.factor(A); !s.ok())
    return Status::error(s.code, "transition region reconstruction: " + s.message);
  Eigen::MatrixXd X;
  if (Status s = solver.solve(rhs, &X); !s.ok()) return s;
  for (size_t k = 0; k < unknowns.size(); ++k) V.row(unknowns[k]) = X.row(static_cast<Eigen::Index>(k));
  if (!V.allFinite()) return Status::error(StatusCode::NumericalError, "transition: non-finite positions");
  return Status::success();
}

}  // namespace mm
