#include "spatial/farthest_point_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mm {

std::vector<int> farthest_point_sampling(const Eigen::MatrixXd& P, int count, int first,
                                         double* min_distance) {
  const int n = static_cast<int>(P.rows());
  std::vector<int> chosen;
  if (n == 0 || count <= 0) return chosen;
  count = std::min(count, n);
  first = std::clamp(first, 0, n - 1);
  chosen.reserve(count);
  // Squared distance of each point to the chosen set; updated incrementally.
  Eigen::VectorXd d2 = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  const double* px = P.col(0).data();
  const double* py = P.col(1).data();
  const double* pz = P.col(2).data();
  double* dd = d2.data();
  // Points in blocks of consecutive indices, each with its bounding box and the largest of its
  // distances. A block the new point cannot come nearer to than that largest distance (its box
  // is farther, with a relative 1e-12 to spare for rounding) keeps every distance: its update is
  // skipped. The scan for the farthest point skips a block whose largest distance cannot beat
  // the scan's threshold. Both skip only work whose outcome is known, so the picks are the ones
  // of the plain O(n·count) loop, bit for bit; surface samples come in vertex and face order,
  // which keeps blocks compact, and late picks touch only the blocks near them.
  constexpr int kBlock = 64;
  const int nb = (n + kBlock - 1) / kBlock;
  std::vector<double> box(6 * static_cast<size_t>(nb));
  std::vector<double> block_max(nb, std::numeric_limits<double>::infinity());
  for (int b = 0; b < nb; ++b) {
    double* q = &box[6 * static_cast<size_t>(b)];
    const int i0 = b * kBlock, i1 = std::min(n, i0 + kBlock);
    q[0] = q[3] = px[i0], q[1] = q[4] = py[i0], q[2] = q[5] = pz[i0];
    for (int i = i0 + 1; i < i1; ++i) {
      q[0] = std::min(q[0], px[i]), q[1] = std::min(q[1], py[i]), q[2] = std::min(q[2], pz[i]);
      q[3] = std::max(q[3], px[i]), q[4] = std::max(q[4], py[i]), q[5] = std::max(q[5], pz[i]);
    }
  }
  int next = first;
  double last = 0;
  for (int k = 0; k < count; ++k) {
    chosen.push_back(next);
    last = std::sqrt(d2[next]);
    d2[next] = -1;  // chosen points never come back
    block_max[next / kBlock] = std::numeric_limits<double>::infinity();  // recomputed below
    const double qx = px[next], qy = py[next], qz = pz[next];
    for (int b = 0; b < nb; ++b) {
      const double* q = &box[6 * static_cast<size_t>(b)];
      const double ex = std::max({q[0] - qx, qx - q[3], 0.0}), ey = std::max({q[1] - qy, qy - q[4], 0.0}),
                   ez = std::max({q[2] - qz, qz - q[5], 0.0});
      if ((ex * ex + ey * ey) + ez * ez > block_max[b] * (1 + 1e-12)) continue;
      // The distances: branch-free, so the compiler vectorises them (the same expression per
      // point, so native and wasm round alike); a chosen point keeps its −1 (every distance is ≥ 0).
      const int i0 = b * kBlock, i1 = std::min(n, i0 + kBlock);
      double m = -1;
      for (int i = i0; i < i1; ++i) {
        const double dx = px[i] - qx, dy = py[i] - qy, dz = pz[i] - qz;
        const double d = (dx * dx + dy * dy) + dz * dz;
        dd[i] = d < dd[i] ? d : dd[i];
        m = dd[i] > m ? dd[i] : m;
      }
      block_max[b] = m;
    }
    // Near-ties (regular samplings have many exact ties in exact arithmetic) go to the lower
    // index: a point must be farther by a relative 1e-9 to win, so last-bit differences of the
    // inputs between platforms (libm, SIMD) do not change which point is chosen. The first
    // threshold lets any distance (≥ 0) win and no chosen point (−1); later ones are ≥ 1e-300.
    int best = -1;
    double threshold = -0.5;
    for (int b = 0; b < nb; ++b) {
      if (!(block_max[b] > threshold)) continue;
      const int i0 = b * kBlock, i1 = std::min(n, i0 + kBlock);
      for (int i = i0; i < i1; ++i)
        if (dd[i] > threshold) {
          best = i;
          threshold = dd[i] * (1 + 1e-9) + 1e-300;
        }
    }
    if (best < 0) break;
    next = best;
  }
  if (min_distance) *min_distance = chosen.size() > 1 ? last : 0.0;
  return chosen;
}

Eigen::MatrixXd SurfaceSamples::positions(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) const {
  Eigen::MatrixXd X(size(), 3);
  for (int s = 0; s < size(); ++s) {
    const int f = face[s];
    X.row(s) = barycentric(s, 0) * V.row(F(f, 0)) + barycentric(s, 1) * V.row(F(f, 1)) +
               barycentric(s, 2) * V.row(F(f, 2));
  }
  return X;
}

SurfaceSamples surface_samples(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int target_count) {
  const int nf = static_cast<int>(F.rows());
  Eigen::VectorXd area(nf);
  Eigen::MatrixXd normal(nf, 3);
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    area[f] = 0.5 * n.norm();
    if (area[f] > 0)
      normal.row(f) = (n / n.norm()).transpose();
    else
      normal.row(f).setZero();
  }
  const double total = area.sum();
  const double cell = target_count > 0 && total > 0 ? total / target_count : 0;

  std::vector<int> faces;
  std::vector<Eigen::Vector3d> bary;
  // Corner samples: one per referenced vertex, in vertex order.
  std::vector<int> first_face(V.rows(), -1), first_corner(V.rows(), -1);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      if (first_face[F(f, k)] < 0) {
        first_face[F(f, k)] = f;
        first_corner[F(f, k)] = k;
      }
  for (int v = 0; v < V.rows(); ++v) {
    if (first_face[v] < 0) continue;
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    w[first_corner[v]] = 1;
    faces.push_back(first_face[v]);
    bary.push_back(w);
  }
  // Interior samples: centroids of the level-L midpoint subdivision. A sub-triangle at level L
  // is described by its barycentric corners; recursion depth is bounded (L ≤ 8).
  struct Tri { Eigen::Vector3d a, b, c; };
  for (int f = 0; f < nf; ++f) {
    if (!(area[f] > 0)) continue;
    int level = 0;
    if (cell > 0) {
      double a = area[f];
      while (a > cell && level < 8) {
        a /= 4;
        ++level;
      }
    }
    std::vector<Tri> tris{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    for (int l = 0; l < level; ++l) {
      std::vector<Tri> next;
      next.reserve(tris.size() * 4);
      for (const Tri& t : tris) {
        const Eigen::Vector3d ab = (t.a + t.b) / 2, bc = (t.b + t.c) / 2, ca = (t.c + t.a) / 2;
        next.push_back({t.a, ab, ca});
        next.push_back({ab, t.b, bc});
        next.push_back({ca, bc, t.c});
        next.push_back({ab, bc, ca});
      }
      tris.swap(next);
    }
    for (const Tri& t : tris) {
      faces.push_back(f);
      bary.push_back((t.a + t.b + t.c) / 3);
    }
  }
  SurfaceSamples S;
  const int n = static_cast<int>(faces.size());
  S.face.resize(n);
  S.barycentric.resize(n, 3);
  S.N.resize(n, 3);
  for (int s = 0; s < n; ++s) {
    S.face[s] = faces[s];
    S.barycentric.row(s) = bary[s].transpose();
    S.N.row(s) = normal.row(faces[s]);
  }
  S.P = S.positions(V, F);
  return S;
}

SurfaceSamples select_samples(const SurfaceSamples& S, const std::vector<int>& index) {
  SurfaceSamples R;
  const int n = static_cast<int>(index.size());
  R.face.resize(n);
  R.barycentric.resize(n, 3);
  R.P.resize(n, 3);
  R.N.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    R.face[i] = S.face[index[i]];
    R.barycentric.row(i) = S.barycentric.row(index[i]);
    R.P.row(i) = S.P.row(index[i]);
    R.N.row(i) = S.N.row(index[i]);
  }
  return R;
}

}  // namespace mm
