#include "mesh/butterfly.h"

#include <algorithm>
#include <cassert>
#include <utility>
#include <vector>

namespace mm {

namespace {

// Undirected edges of F (sorted, unique) and, per edge, the faces using it. Deterministic: the
// edge order is (i, j) ascending, faces in ascending index.
struct ButterflyEdges {
  std::vector<std::pair<int, int>> edges;
  std::vector<std::vector<int>> faces;
  int find(int a, int b) const {
    const std::pair<int, int> k{std::min(a, b), std::max(a, b)};
    const auto it = std::lower_bound(edges.begin(), edges.end(), k);
    return (it != edges.end() && *it == k) ? static_cast<int>(it - edges.begin()) : -1;
  }
};

ButterflyEdges butterfly_edges(const Eigen::MatrixXi& F) {
  std::vector<std::pair<std::pair<int, int>, int>> uses;
  uses.reserve(F.rows() * 3);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      uses.push_back({{std::min(a, b), std::max(a, b)}, f});
    }
  std::sort(uses.begin(), uses.end());
  ButterflyEdges e;
  for (const auto& u : uses) {
    if (e.edges.empty() || e.edges.back() != u.first) {
      e.edges.push_back(u.first);
      e.faces.emplace_back();
    }
    e.faces.back().push_back(u.second);
  }
  return e;
}

// The vertex of face f that is neither a nor b.
int butterfly_opposite(const Eigen::MatrixXi& F, int f, int a, int b) {
  for (int k = 0; k < 3; ++k)
    if (F(f, k) != a && F(f, k) != b) return F(f, k);
  return -1;
}

// The wing vertex across edge (x, y) from face `not_f`: the opposite vertex of the other face of
// that edge, or -1 when the edge is a boundary or non-manifold edge.
int butterfly_wing(const ButterflyEdges& E, const Eigen::MatrixXi& F, int x, int y, int not_f) {
  const int e = E.find(x, y);
  if (e < 0 || E.faces[e].size() != 2) return -1;
  const int g = E.faces[e][0] == not_f ? E.faces[e][1] : E.faces[e][0];
  return butterfly_opposite(F, g, x, y);
}

}  // namespace

ButterflyResult butterfly_subdivide(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  const int n = static_cast<int>(V.rows());
  const ButterflyEdges E = butterfly_edges(F);
  const int ne = static_cast<int>(E.edges.size());
  // Boundary chains: for a boundary edge a→b (face orientation), the boundary vertex before a
  // and after b. A vertex with exactly one outgoing and one incoming boundary edge is a simple
  // boundary vertex; elsewhere the four-point rule falls back to the midpoint.
  std::vector<int> next_b(n, -1), prev_b(n, -1), out_count(n, 0), in_count(n, 0);
  for (int e = 0; e < ne; ++e) {
    if (E.faces[e].size() != 1) continue;
    const int f = E.faces[e][0];
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (std::min(a, b) == E.edges[e].first && std::max(a, b) == E.edges[e].second) {
        next_b[a] = b;
        prev_b[b] = a;
        ++out_count[a];
        ++in_count[b];
      }
    }
  }
  ButterflyResult out;
  out.coarse_vertices = n;
  out.V.resize(n + ne, 3);
  out.V.topRows(n) = V;
  for (int e = 0; e < ne; ++e) {
    const int a = E.edges[e].first, b = E.edges[e].second;
    const Eigen::RowVector3d mid = 0.5 * (V.row(a) + V.row(b));
    Eigen::RowVector3d p = mid;
    const auto& fs = E.faces[e];
    if (fs.size() == 2) {
      const int c = butterfly_opposite(F, fs[0], a, b), d = butterfly_opposite(F, fs[1], a, b);
      const int w1 = butterfly_wing(E, F, a, c, fs[0]), w2 = butterfly_wing(E, F, b, c, fs[0]);
      const int w3 = butterfly_wing(E, F, a, d, fs[1]), w4 = butterfly_wing(E, F, b, d, fs[1]);
      if (c >= 0 && d >= 0) {
        if (w1 >= 0 && w2 >= 0 && w3 >= 0 && w4 >= 0)
          p = mid + 0.125 * (V.row(c) + V.row(d)) - 0.0625 * (V.row(w1) + V.row(w2) + V.row(w3) + V.row(w4));
        else
          p = 0.375 * (V.row(a) + V.row(b)) + 0.125 * (V.row(c) + V.row(d));
      }
    } else if (fs.size() == 1) {
      // Orient the edge as the face does: s → t.
      int s = a, t = b;
      if (next_b[a] != b) std::swap(s, t);
      const bool simple = next_b[s] == t && out_count[s] == 1 && in_count[s] == 1 && out_count[t] == 1 &&
                          in_count[t] == 1 && prev_b[s] >= 0 && next_b[t] >= 0 && prev_b[s] != t && next_b[t] != s;
      if (simple) p = 0.5625 * (V.row(s) + V.row(t)) - 0.0625 * (V.row(prev_b[s]) + V.row(next_b[t]));
    }
    out.V.row(n + e) = p;
  }
  out.F.resize(4 * F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    const int v0 = F(f, 0), v1 = F(f, 1), v2 = F(f, 2);
    const int m01 = n + E.find(v0, v1), m12 = n + E.find(v1, v2), m20 = n + E.find(v2, v0);
    out.F.row(4 * f + 0) << v0, m01, m20;
    out.F.row(4 * f + 1) << v1, m12, m01;
    out.F.row(4 * f + 2) << v2, m20, m12;
    out.F.row(4 * f + 3) << m01, m12, m20;
  }
  return out;
}

ButterflyResult butterfly_subdivide(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int levels) {
  ButterflyResult r;
  r.V = V;
  r.F = F;
  r.coarse_vertices = static_cast<int>(V.rows());
  for (int l = 0; l < levels; ++l) {
    ButterflyResult next = butterfly_subdivide(r.V, r.F);
    r.V = std::move(next.V);
    r.F = std::move(next.F);
  }
  return r;
}

void butterfly_coarsen(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int levels, int coarse_vertices,
                       Eigen::MatrixXd* Vout, Eigen::MatrixXi* Fout) {
  long stride = 1;
  for (int l = 0; l < levels; ++l) stride *= 4;
  assert(F.rows() % stride == 0 && "F is not a butterfly subdivision of this many levels");
  assert(coarse_vertices <= V.rows() && "more coarse vertices than fine ones");
  *Vout = V.topRows(coarse_vertices);
  const long nf = F.rows() / stride;
  Fout->resize(nf, 3);
  // Corner k of coarse face f is the first corner of its k-th child at every level.
  for (long f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) (*Fout)(f, k) = F(stride * f + k * (stride / 4 > 0 ? stride / 4 : 0), 0);
  if (levels == 0) *Fout = F;
}

}  // namespace mm
