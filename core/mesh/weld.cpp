#include "mesh/weld.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "mesh/mesh.h"

namespace mm {

WeldResult weld_vertices(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const WeldOptions& opt) {
  const int n = static_cast<int>(V.rows());
  WeldResult out;
  out.to_welded.resize(n);
  double tol = 0;
  if (V.allFinite()) tol = opt.tolerance * bounding_box_diagonal(V);

  // Sort vertices by x, then sweep: candidates for merging lie within tol in x.
  // Each vertex joins the group of the earliest (lowest index) vertex within tol, so
  // numbering follows first occurrence and is independent of the sort.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  // Non-finite vertices sort last and are never merged (NaN breaks the ordering otherwise).
  std::vector<double> key(n);
  for (int v = 0; v < n; ++v)
    key[v] = V.row(v).allFinite() ? V(v, 0) : std::numeric_limits<double>::infinity();
  std::sort(order.begin(), order.end(), [&key](int a, int b) {
    if (key[a] != key[b]) return key[a] < key[b];
    return a < b;
  });
  // Union-find whose root is always the smallest index of its group.
  std::vector<int> rep(n);
  std::iota(rep.begin(), rep.end(), 0);
  auto find = [&rep](int x) {
    while (rep[x] != x) x = rep[x] = rep[rep[x]];
    return x;
  };
  const double tol2 = tol * tol;
  for (size_t s = 0; s < order.size(); ++s) {
    const int a = order[s];
    for (size_t t = s + 1; t < order.size(); ++t) {
      const int b = order[t];
      if (!std::isfinite(key[b]) || key[b] - key[a] > tol) break;
      if ((V.row(a) - V.row(b)).squaredNorm() <= tol2) {
        const int ra = find(a), rb = find(b);
        if (ra != rb) rep[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  }
  for (int v = 0; v < n; ++v) rep[v] = find(v);
  std::vector<int> id(n, -1);
  int count = 0;
  for (int v = 0; v < n; ++v) {
    if (id[rep[v]] < 0) id[rep[v]] = count++;
    out.to_welded[v] = id[rep[v]];
  }
  out.V.resize(count, 3);
  std::vector<char> placed(count, 0);
  for (int v = 0; v < n; ++v) {
    const int w = out.to_welded[v];
    if (!placed[w]) {
      out.V.row(w) = V.row(v);
      placed[w] = 1;
    }
  }
  out.F.resize(F.rows(), 3);
  out.face_map.resize(F.rows());
  int rows = 0;
  for (int f = 0; f < F.rows(); ++f) {
    Eigen::Vector3i t;
    bool in_range = true;
    for (int c = 0; c < 3; ++c) {
      const int v = F(f, c);
      if (v < 0 || v >= n) { in_range = false; break; }
      t[c] = out.to_welded[v];
    }
    if (!in_range) continue;
    if (opt.drop_degenerate_faces && (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])) continue;
    out.F.row(rows) = t.transpose();
    out.face_map[rows++] = f;
  }
  out.F.conservativeResize(rows, 3);
  out.face_map.conservativeResize(rows);
  return out;
}

Eigen::MatrixXd unweld(const Eigen::MatrixXd& welded_values, const Eigen::VectorXi& to_welded) {
  Eigen::MatrixXd out(to_welded.size(), welded_values.cols());
  for (int v = 0; v < to_welded.size(); ++v) out.row(v) = welded_values.row(to_welded[v]);
  return out;
}

}  // namespace mm
