// Linear-time loading (issue 18): weld_vertices (spatial hash) and boundary_loops (buckets, no
// ordered maps) must give exactly what the previous implementations gave — an x-sweep comparing
// every pair of vertices that share an x coordinate, and std::map edge counts. Those are kept
// here as the reference and compared on real meshes (glTF primitives split at seams, scans) and
// on grids where thousands of vertices share each x coordinate. No timing here: bench/ has the rows.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/asset.h"
#include "mesh/mesh.h"
#include "mesh/topology.h"
#include "mesh/weld.h"
#include "test_support.h"

namespace {

using namespace mm;

// The previous weld: sort by x, sweep pairs within tol in x, union-find with the smallest root.
WeldResult reference_weld(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const WeldOptions& opt = {}) {
  const int n = static_cast<int>(V.rows());
  WeldResult out;
  out.to_welded.resize(n);
  double tol = 0;
  if (V.allFinite()) tol = opt.tolerance * bounding_box_diagonal(V);
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::vector<double> key(n);
  for (int v = 0; v < n; ++v) key[v] = V.row(v).allFinite() ? V(v, 0) : std::numeric_limits<double>::infinity();
  std::sort(order.begin(), order.end(), [&key](int a, int b) { return key[a] != key[b] ? key[a] < key[b] : a < b; });
  std::vector<int> rep(n);
  std::iota(rep.begin(), rep.end(), 0);
  auto find = [&rep](int x) {
    while (rep[x] != x) x = rep[x] = rep[rep[x]];
    return x;
  };
  for (size_t s = 0; s < order.size(); ++s) {
    const int a = order[s];
    for (size_t t = s + 1; t < order.size(); ++t) {
      const int b = order[t];
      if (!std::isfinite(key[b]) || key[b] - key[a] > tol) break;
      if ((V.row(a) - V.row(b)).squaredNorm() <= tol * tol) {
        const int ra = find(a), rb = find(b);
        if (ra != rb) rep[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  }
  std::vector<int> id(n, -1);
  int count = 0;
  for (int v = 0; v < n; ++v) {
    const int r = find(v);
    if (id[r] < 0) id[r] = count++;
    out.to_welded[v] = id[r];
  }
  out.V.resize(count, 3);
  std::vector<char> placed(count, 0);
  for (int v = 0; v < n; ++v)
    if (!placed[out.to_welded[v]]) out.V.row(out.to_welded[v]) = V.row(v), placed[out.to_welded[v]] = 1;
  out.F.resize(F.rows(), 3);
  out.face_map.resize(F.rows());
  int rows = 0;
  for (int f = 0; f < F.rows(); ++f) {
    Eigen::Vector3i t;
    bool ok = true;
    for (int c = 0; c < 3 && ok; ++c) {
      ok = F(f, c) >= 0 && F(f, c) < n;
      if (ok) t[c] = out.to_welded[F(f, c)];
    }
    if (!ok || (opt.drop_degenerate_faces && (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]))) continue;
    out.F.row(rows) = t.transpose();
    out.face_map[rows++] = f;
  }
  out.F.conservativeResize(rows, 3);
  out.face_map.conservativeResize(rows);
  return out;
}

// The previous boundary tracing: std::map edge counts, per-vertex successor lists.
std::vector<std::vector<int>> reference_boundary_loops(const Eigen::MatrixXi& F, int n) {
  std::map<std::pair<int, int>, int> count;
  auto valid = [n](int a, int b) { return a != b && a >= 0 && b >= 0 && a < n && b < n; };
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      if (valid(a, b)) ++count[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<std::vector<int>> next(n);
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      if (valid(a, b) && count[{std::min(a, b), std::max(a, b)}] == 1) next[a].push_back(b);
    }
  for (auto& l : next) std::sort(l.begin(), l.end());
  std::vector<std::vector<int>> loops;
  for (int s = 0; s < n; ++s)
    while (!next[s].empty()) {
      std::vector<int> loop{s};
      int v = s;
      while (!next[v].empty()) {
        const int w = next[v].front();
        next[v].erase(next[v].begin());
        if (w == s) break;
        loop.push_back(w);
        v = w;
      }
      loops.push_back(std::move(loop));
    }
  return loops;
}

void expect_same_weld(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const WeldOptions& opt, const std::string& what) {
  const WeldResult a = weld_vertices(V, F, opt), b = reference_weld(V, F, opt);
  ASSERT_EQ(a.to_welded.size(), b.to_welded.size()) << what;
  EXPECT_TRUE(a.to_welded == b.to_welded) << what;
  ASSERT_EQ(a.V.rows(), b.V.rows()) << what;
  EXPECT_TRUE((a.V.array() == b.V.array() || (a.V.array().isNaN() && b.V.array().isNaN())).all()) << what;
  ASSERT_EQ(a.F.rows(), b.F.rows()) << what;
  EXPECT_TRUE(a.F == b.F) << what;
  EXPECT_TRUE(a.face_map == b.face_map) << what;
  EXPECT_TRUE(boundary_loops(a.F, static_cast<int>(a.V.rows())) == reference_boundary_loops(b.F, static_cast<int>(b.V.rows())))
      << what;
}

// An nx by ny grid of unit quads in the z = 0 plane, every quad with its own four vertices (each
// interior grid point appears 4 times; without jitter ~2·ny vertices share each x coordinate),
// moved by up to ±jitter/2 (absolute, fixed LCG), with every `hole`-th quad left out.
void split_grid(int nx, int ny, double jitter, int hole, Eigen::MatrixXd* V, Eigen::MatrixXi* F) {
  unsigned state = 7u;
  auto rnd = [&]() {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / 16777216.0 - 0.5;
  };
  std::vector<Eigen::RowVector3d> P;
  std::vector<Eigen::RowVector3i> T;
  int q = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i, ++q) {
      if (hole > 0 && q % hole == hole / 2) continue;
      const int base = static_cast<int>(P.size());
      for (int c = 0; c < 4; ++c) {
        const int di = c == 1 || c == 2, dj = c >= 2;
        P.emplace_back(i + di + jitter * rnd(), j + dj + jitter * rnd(), jitter * rnd());
      }
      T.emplace_back(base, base + 1, base + 2);
      T.emplace_back(base, base + 2, base + 3);
    }
  V->resize(static_cast<Eigen::Index>(P.size()), 3);
  for (size_t k = 0; k < P.size(); ++k) V->row(static_cast<Eigen::Index>(k)) = P[k];
  F->resize(static_cast<Eigen::Index>(T.size()), 3);
  for (size_t k = 0; k < T.size(); ++k) F->row(static_cast<Eigen::Index>(k)) = T[k];
}

TEST(LinearLoading, WeldMatchesSweepOnRealMeshes) {
  for (const std::string file : {"anim/Fox/glTF-Binary/Fox.glb", "anim/CesiumMan/CesiumMan.glb",
                                 "anim/RobotExpressive/RobotExpressive.glb", "anim/KayKit/Knight.glb",
                                 "edit/armadillo.ply", "pose/camel_ref.ply"}) {
    io::LoadResult r = io::load_asset(test::data_path(file));
    ASSERT_TRUE(r.status.ok()) << file << ": " << r.status.message;
    const Eigen::MatrixXd& V = r.asset.V_raw;
    const Eigen::MatrixXi& F = r.asset.F_raw;
    for (double tol : {0.0, 1e-7, 1e-4, 1e-2}) {
      WeldOptions opt;
      opt.tolerance = tol;
      expect_same_weld(V, F, opt, file + " tolerance " + std::to_string(tol));
    }
  }
}

// Grids: every x coordinate is shared by 2·(ny+1) vertices (the quadratic case of the sweep),
// exact duplicates, jitter below and around the tolerance, holes (inner boundary loops), and a
// non-finite vertex (which switches the weld to exact duplicates).
TEST(LinearLoading, WeldMatchesSweepOnGridsWithSharedCoordinates) {
  for (double jitter : {0.0, 1e-9, 1e-6, 3e-4}) {
    Eigen::MatrixXd V;
    Eigen::MatrixXi F;
    split_grid(60, 50, jitter, 7, &V, &F);
    for (double tol : {0.0, 1e-7, 1e-5, 2e-4}) {
      WeldOptions opt;
      opt.tolerance = tol;
      opt.drop_degenerate_faces = tol < 1e-4;
      expect_same_weld(V, F, opt, "grid jitter " + std::to_string(jitter) + " tolerance " + std::to_string(tol));
    }
    V(5, 1) = std::numeric_limits<double>::quiet_NaN();
    expect_same_weld(V, F, {}, "grid with a NaN vertex, jitter " + std::to_string(jitter));
  }
  // Shifted far from the origin: cells must not depend on the absolute position.
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  split_grid(40, 30, 1e-9, 5, &V, &F);
  V.rowwise() += Eigen::RowVector3d(1e6, -3e5, 2e4);
  expect_same_weld(V, F, {}, "shifted grid");
}

// Boundary loops on meshes with several loops, non-manifold boundaries (a bow-tie vertex shared
// by two loops) and out-of-range / repeated indices, against the std::map version.
TEST(LinearLoading, BoundaryLoopsMatchMapVersion) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  split_grid(30, 20, 0.0, 4, &V, &F);
  const WeldResult w = weld_vertices(V, F);
  const int n = static_cast<int>(w.V.rows());
  EXPECT_TRUE(boundary_loops(w.F, n) == reference_boundary_loops(w.F, n));
  EXPECT_GT(boundary_loops(w.F, n).size(), 10u);
  // Remove a diagonal band of faces: quads touching only at a corner make bow-tie boundaries.
  Eigen::MatrixXi G(w.F.rows(), 3);
  int rows = 0;
  for (int f = 0; f < w.F.rows(); ++f)
    if ((f / 2) % 5 != (f / 60) % 5) G.row(rows++) = w.F.row(f);
  G.conservativeResize(rows, 3);
  EXPECT_TRUE(boundary_loops(G, n) == reference_boundary_loops(G, n));
  Eigen::MatrixXi H = G;
  H(0, 0) = -1;
  H(1, 1) = n + 5;
  H(2, 2) = H(2, 1);
  EXPECT_TRUE(boundary_loops(H, n) == reference_boundary_loops(H, n));
  for (const std::string file : {"edit/camelhead.ply", "edit/hand_lowres.ply", "pose/camel_ref.ply"}) {
    const Mesh m = test::load_mesh(file);
    EXPECT_TRUE(boundary_loops(m.F, m.num_vertices()) == reference_boundary_loops(m.F, m.num_vertices())) << file;
  }
}

}  // namespace
