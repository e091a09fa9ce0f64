// Tests of core/spatial: BVH closest point / rays / inside test against brute force,
// farthest-point sampling invariants, plane quadrics, and uniform-grid box queries.
#include <gtest/gtest.h>

#include <iostream>
#include <limits>
#include <string>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/threads.h"
#include "io/asset.h"
#include "mesh/midpoint_subdivide.h"
#include "spatial/farthest_point_sampling.h"
#include "spatial/quadric.h"
#include "spatial/triangle_bvh.h"
#include "spatial/uniform_grid.h"
#include "test_support.h"

namespace {

// Unit cube [0,1]^3, 12 outward-facing triangles.
void unit_cube(Eigen::MatrixXd* V, Eigen::MatrixXi* F) {
  V->resize(8, 3);
  *V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  F->resize(12, 3);
  *F << 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3;
}

// A deterministic pseudo-random sequence (LCG) for test points.
struct Lcg {
  uint64_t s = 12345;
  double next() {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(s >> 11) / double(1ULL << 53);
  }
};

// A sphere-ish icosphere-free soup: UV sphere with n×n cells.
void uv_sphere(int n, Eigen::MatrixXd* V, Eigen::MatrixXi* F) {
  const int rings = n, segs = 2 * n;
  V->resize((rings - 1) * segs + 2, 3);
  int k = 0;
  V->row(k++) << 0, 0, 1;
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segs; ++s) {
      const double th = M_PI * r / rings, ph = 2 * M_PI * s / segs;
      V->row(k++) << std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th);
    }
  V->row(k++) << 0, 0, -1;
  std::vector<Eigen::Vector3i> f;
  for (int s = 0; s < segs; ++s) f.push_back({0, 1 + s, 1 + (s + 1) % segs});
  for (int r = 0; r < rings - 2; ++r)
    for (int s = 0; s < segs; ++s) {
      const int a = 1 + r * segs + s, b = 1 + r * segs + (s + 1) % segs;
      const int c = a + segs, d = b + segs;
      f.push_back({a, c, d});
      f.push_back({a, d, b});
    }
  const int south = k - 1, last = 1 + (rings - 2) * segs;
  for (int s = 0; s < segs; ++s) f.push_back({south, last + (s + 1) % segs, last + s});
  F->resize(f.size(), 3);
  for (size_t i = 0; i < f.size(); ++i) F->row(i) = f[i].transpose();
}

}  // namespace

TEST(SpatialBvh, ClosestPointMatchesBruteForce) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  uv_sphere(12, &V, &F);
  mm::TriangleBvh bvh(V, F);
  Lcg rng;
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector3d p(3 * rng.next() - 1.5, 3 * rng.next() - 1.5, 3 * rng.next() - 1.5);
    double best = 1e300;
    for (int f = 0; f < F.rows(); ++f) {
      Eigen::Vector3d b;
      const Eigen::Vector3d c = mm::closest_point_on_triangle(p, V.row(F(f, 0)), V.row(F(f, 1)), V.row(F(f, 2)), &b);
      best = std::min(best, (c - p).squaredNorm());
    }
    const mm::ClosestPoint cp = bvh.closest_point(p);
    ASSERT_GE(cp.face, 0);
    EXPECT_NEAR(cp.sq_distance, best, 1e-12);
    // The barycentric weights reproduce the point.
    const Eigen::Vector3d r = cp.barycentric[0] * V.row(F(cp.face, 0)).transpose() +
                              cp.barycentric[1] * V.row(F(cp.face, 1)).transpose() +
                              cp.barycentric[2] * V.row(F(cp.face, 2)).transpose();
    EXPECT_LT((r - cp.point).norm(), 1e-12);
  }
}

TEST(SpatialBvh, InsideAndWinding) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  unit_cube(&V, &F);
  mm::TriangleBvh bvh(V, F);
  EXPECT_TRUE(bvh.inside({0.5, 0.5, 0.5}));
  EXPECT_TRUE(bvh.inside({0.1, 0.9, 0.2}));
  EXPECT_FALSE(bvh.inside({1.5, 0.5, 0.5}));
  EXPECT_FALSE(bvh.inside({-0.1, -0.1, 2}));
  EXPECT_EQ(bvh.ray_winding({0.5, 0.5, 0.5}, {0.3, 0.2, 1}), 1);
  // Inverted orientation: |winding| still says inside.
  Eigen::MatrixXi Fi = F;
  Fi.col(1).swap(Fi.col(2));
  mm::TriangleBvh inv(V, Fi);
  EXPECT_EQ(inv.ray_winding({0.5, 0.5, 0.5}, {0.3, 0.2, 1}), -1);
  EXPECT_TRUE(inv.inside({0.5, 0.5, 0.5}));
  // Two overlapping cubes (a multi-part character): the overlap is inside.
  Eigen::MatrixXd V2(16, 3);
  V2 << V, (V.array() + 0.5).matrix();
  Eigen::MatrixXi F2(24, 3);
  F2 << F, (F.array() + 8).matrix();
  mm::TriangleBvh two(V2, F2);
  EXPECT_TRUE(two.inside({0.75, 0.75, 0.75}));
  EXPECT_TRUE(two.inside({1.25, 1.25, 1.25}));
  EXPECT_FALSE(two.inside({1.25, 0.25, 0.25}));
}

// inside() casts its 7 rays through a projected grid per direction (triangle_bvh.cpp): it must
// answer as the majority of the tree's own ray_winding along the same directions, on real meshes
// (interpenetrating parts, open surfaces, an axis-aligned cube) and at the hardest points: the
// vertices themselves (rays through edges and corners), points just off the surface, points far
// outside and random points around the mesh.
TEST(SpatialBvh, InsideGridsAnswerAsTheRayTraversal) {
  const auto majority = [](const mm::TriangleBvh& bvh, const Eigen::Vector3d& p) {
    int votes = 0;
    for (int r = 0; r < 7; ++r) votes += std::abs(bvh.ray_winding(p, mm::TriangleBvh::inside_direction(r))) >= 1;
    return votes >= 4;
  };
  struct Mesh {
    std::string name;
    Eigen::MatrixXd V;
    Eigen::MatrixXi F;
  };
  std::vector<Mesh> meshes;
  for (const char* rel : {"anim/KayKit/Knight.glb", "anim/RobotExpressive/RobotExpressive.glb", "anim/human_woman.ply",
                          "edit/camelhead.ply", "edit/hand_lowres.ply"}) {
    const mm::io::LoadResult r = mm::io::load_asset(mm::test::data_path(rel));
    ASSERT_TRUE(r.status.ok()) << rel << ": " << r.status.message;
    meshes.push_back({rel, r.asset.V_raw, r.asset.F_raw});
  }
  meshes.push_back({"cube", {}, {}});
  unit_cube(&meshes.back().V, &meshes.back().F);
  Lcg rng;
  for (const Mesh& m : meshes) {
    const mm::TriangleBvh built(m.V, m.F);
    const mm::TriangleBvh bvh = built;  // a copy shares (or builds) the same grids
    const Eigen::Vector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
    const double diag = (hi - lo).norm();
    std::vector<Eigen::Vector3d> pts;
    for (int v = 0; v < m.V.rows(); v += std::max<int>(1, int(m.V.rows()) / 1500)) pts.push_back(m.V.row(v).transpose());
    for (int f = 0; f < m.F.rows(); f += std::max<int>(1, int(m.F.rows()) / 1500)) {
      const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
      const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
      if (!n.allFinite()) continue;
      for (double off : {-1e-3, -1e-9, 0.0, 1e-9, 1e-3}) pts.push_back((a + b + c) / 3 + off * diag * n);
      pts.push_back(0.5 * (a + b));  // on an edge
    }
    for (int k = 0; k < 3000; ++k) {
      Eigen::Vector3d x;
      for (int d = 0; d < 3; ++d) x[d] = lo[d] - 0.2 * diag + (hi[d] - lo[d] + 0.4 * diag) * rng.next();
      pts.push_back(x);
    }
    pts.push_back(lo - 10 * diag * Eigen::Vector3d::Ones());
    pts.push_back(hi + 1e3 * diag * Eigen::Vector3d(1, -2, 3));
    // The rays' answer once per point (7 traversals each: most of the test's time, minutes under ASan).
    std::vector<char> rays(pts.size());
    for (size_t k = 0; k < pts.size(); ++k) rays[k] = majority(built, pts[k]);
    // The grids are built after max(256, #F / 8) queries on the tree: ask until they are, then once more.
    int n_inside = 0, mismatches = 0;
    for (int pass = 0; pass < 100; ++pass) {
      const bool ready = bvh.inside_grids_ready();
      n_inside = 0;
      for (size_t k = 0; k < pts.size(); ++k) {
        const Eigen::Vector3d& p = pts[k];
        const bool g = bvh.inside(p);
        n_inside += g;
        if (g != static_cast<bool>(rays[k]) && ++mismatches <= 5)
          ADD_FAILURE() << m.name << ": inside() " << g << " at " << p.transpose() << ", the rays say otherwise";
      }
      if (ready) break;
    }
    EXPECT_TRUE(bvh.inside_grids_ready()) << m.name;
    EXPECT_EQ(mismatches, 0) << m.name;
    EXPECT_GT(n_inside, 0) << m.name;
    EXPECT_LT(n_inside, int(pts.size())) << m.name;
    std::cout << "[ " << m.name << " ] " << pts.size() << " points, " << n_inside << " inside\n";
  }
  EXPECT_FALSE(mm::TriangleBvh().inside({0, 0, 0}));
  EXPECT_FALSE(mm::TriangleBvh(meshes.back().V, meshes.back().F).inside({std::nan(""), 0.5, 0.5}));
}

// From 16,384 triangles up, with two threads the root's halves are built on two threads; the node
// array (pre-order) and the triangle order are the same as on one thread.
TEST(SpatialBvh, TheBuildGivesTheSameTreeOnAnyThreadCount) {
  const mm::io::LoadResult r = mm::io::load_asset(mm::test::data_path("anim/human_woman.ply"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const mm::Mesh m{r.asset.V_raw, r.asset.F_raw};
  const mm::Mesh fine = mm::midpoint_subdivide(m);  // 55k triangles
  ASSERT_GE(fine.F.rows(), 3 * 16384);
  for (const mm::Mesh* mesh : {&m, &fine}) {
    std::uint64_t h[3];
    const int counts[3] = {1, 2, 4};
    std::vector<mm::ClosestPoint> answers[3];
    for (int t = 0; t < 3; ++t) {
      mm::set_max_threads(counts[t]);
      const mm::TriangleBvh bvh(mesh->V, mesh->F);
      h[t] = bvh.fingerprint();
      for (int v = 0; v < mesh->V.rows(); v += 97) answers[t].push_back(bvh.closest_point(mesh->V.row(v).transpose() * 1.01));
    }
    mm::set_max_threads(0);
    EXPECT_EQ(h[0], h[1]) << mesh->F.rows() << " triangles";
    EXPECT_EQ(h[0], h[2]) << mesh->F.rows() << " triangles";
    for (int t = 1; t < 3; ++t)
      for (size_t i = 0; i < answers[0].size(); ++i) {
        ASSERT_EQ(answers[0][i].face, answers[t][i].face);
        ASSERT_EQ(answers[0][i].sq_distance, answers[t][i].sq_distance);
      }
  }
  // The hash sees the tree: a different mesh (one vertex moved) gives another.
  mm::Mesh moved = fine;
  moved.V(0, 0) += 1e-9;
  EXPECT_NE(mm::TriangleBvh(fine.V, fine.F).fingerprint(), mm::TriangleBvh(moved.V, moved.F).fingerprint());
}

TEST(SpatialBvh, SegmentHits) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  unit_cube(&V, &F);
  mm::TriangleBvh bvh(V, F);
  EXPECT_TRUE(bvh.segment_hits({0.5, 0.5, 0.5}, {0.5, 0.5, 2}));
  EXPECT_FALSE(bvh.segment_hits({0.2, 0.5, 0.5}, {0.8, 0.5, 0.5}));
  EXPECT_FALSE(bvh.segment_hits({2, 2, 2}, {3, 3, 3}));
  int n = 0;
  bvh.for_each_overlapping({0.9, 0.9, 0.9}, {1.1, 1.1, 1.1}, [&](int) { ++n; });
  EXPECT_GT(n, 0);
}

TEST(SpatialSampling, FarthestPointSamplingSpreadsAndIsDeterministic) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  uv_sphere(16, &V, &F);
  double r1 = 0;
  const std::vector<int> a = mm::farthest_point_sampling(V, 40, 0, &r1);
  const std::vector<int> b = mm::farthest_point_sampling(V, 40, 0);
  EXPECT_EQ(a, b);
  ASSERT_EQ(a.size(), 40u);
  std::vector<int> sorted = a;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::unique(sorted.begin(), sorted.end()), sorted.end());
  // Every vertex is within the sampling radius of a chosen point (covering property), and the
  // chosen points are at least that far apart (packing property).
  for (int i = 0; i < V.rows(); ++i) {
    double d = 1e300;
    for (int s : a) d = std::min(d, (V.row(i) - V.row(s)).norm());
    EXPECT_LE(d, r1 + 1e-12);
  }
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = i + 1; j < a.size(); ++j) EXPECT_GE((V.row(a[i]) - V.row(a[j])).norm(), r1 - 1e-12);
  // On a unit sphere, 40 well-spread points are ~0.5 apart (area 4π / 40 per point).
  EXPECT_GT(r1, 0.3);
  EXPECT_EQ(mm::farthest_point_sampling(V, 1000, 0).size(), size_t(V.rows()));
}

// The plain O(n·count) farthest-point sampling that the blocked one (spatial/
// farthest_point_sampling.cpp) must reproduce pick for pick.
std::vector<int> fps_reference(const Eigen::MatrixXd& P, int count, int first, double* min_distance) {
  const int n = int(P.rows());
  std::vector<int> chosen;
  if (n == 0 || count <= 0) return chosen;
  count = std::min(count, n);
  Eigen::VectorXd d2 = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  int next = std::clamp(first, 0, n - 1);
  double last = 0;
  for (int k = 0; k < count; ++k) {
    chosen.push_back(next);
    last = std::sqrt(d2[next]);
    d2[next] = -1;
    for (int i = 0; i < n; ++i) {
      const double dx = P(i, 0) - P(next, 0), dy = P(i, 1) - P(next, 1), dz = P(i, 2) - P(next, 2);
      const double d = (dx * dx + dy * dy) + dz * dz;
      d2[i] = d < d2[i] ? d : d2[i];
    }
    int best = -1;
    double threshold = -0.5;
    for (int i = 0; i < n; ++i)
      if (d2[i] > threshold) best = i, threshold = d2[i] * (1 + 1e-9) + 1e-300;
    if (best < 0) break;
    next = best;
  }
  *min_distance = chosen.size() > 1 ? last : 0.0;
  return chosen;
}

// The blocked sampling skips blocks whose distances cannot change or win: the picks and the
// sampling radius must be the plain loop's exactly, on surface samples of real meshes (blocks
// compact), the same points shuffled (blocks spread over the whole mesh), a regular grid (exact
// ties everywhere) and points with duplicates.
TEST(SpatialSampling, BlockedFarthestPointsEqualThePlainLoop) {
  std::vector<std::pair<std::string, Eigen::MatrixXd>> sets;
  for (const char* rel : {"anim/human_woman.ply", "anim/KayKit/Knight.glb", "edit/camelhead.ply"}) {
    const mm::io::LoadResult r = mm::io::load_asset(mm::test::data_path(rel));
    ASSERT_TRUE(r.status.ok()) << rel;
    const Eigen::MatrixXd S = mm::surface_samples(r.asset.V_raw, r.asset.F_raw, 2000).P;
    sets.push_back({rel, S.topRows(std::min<Eigen::Index>(S.rows(), 3000))});  // the plain loop is quadratic
  }
  {
    Eigen::MatrixXd S = sets[0].second;
    std::vector<int> perm(S.rows());
    for (int i = 0; i < int(perm.size()); ++i) perm[i] = i;
    Lcg rng;
    for (int i = int(perm.size()) - 1; i > 0; --i) std::swap(perm[i], perm[int(rng.next() * (i + 1))]);
    Eigen::MatrixXd T(S.rows(), 3);
    for (int i = 0; i < int(perm.size()); ++i) T.row(i) = S.row(perm[i]);
    sets.push_back({"shuffled woman", T});
  }
  {
    Eigen::MatrixXd G(30 * 30 * 4, 3);
    int k = 0;
    for (int x = 0; x < 30; ++x)
      for (int y = 0; y < 30; ++y)
        for (int z = 0; z < 4; ++z) G.row(k++) << x * 0.1, y * 0.1, z * 0.1;
    sets.push_back({"grid", G});
    Eigen::MatrixXd D(2 * G.rows(), 3);
    D << G, G;
    sets.push_back({"grid twice", D});
  }
  for (const auto& [name, P] : sets)
    for (const auto& [count, first] : {std::pair<int, int>{200, 0}, {int(P.rows()), 7}, {int(P.rows()) / 2, int(P.rows()) - 1}}) {
      double ra = -1, rb = -1;
      const std::vector<int> a = mm::farthest_point_sampling(P, count, first, &ra);
      const std::vector<int> b = fps_reference(P, count, first, &rb);
      EXPECT_EQ(a, b) << name << ", " << count << " of " << P.rows() << " from " << first;
      EXPECT_EQ(ra, rb) << name;
    }
}

TEST(SpatialSampling, SurfaceSamplesCoverFacesUniformly) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  unit_cube(&V, &F);
  const mm::SurfaceSamples S = mm::surface_samples(V, F, 1000);
  // 8 corners + 12 faces × 4^L centroids with area 0.5/4^L ≤ 6/1000 → L = 4 (256 each).
  EXPECT_EQ(S.size(), 8 + 12 * 256);
  for (int s = 0; s < S.size(); ++s) {
    EXPECT_NEAR(S.barycentric.row(s).sum(), 1.0, 1e-12);
    EXPECT_GE(S.barycentric.row(s).minCoeff(), 0.0);
    EXPECT_NEAR(S.N.row(s).norm(), 1.0, 1e-12);
  }
  // Deformed copy: positions follow the vertices.
  const Eigen::MatrixXd V2 = 2 * V;
  EXPECT_LT((S.positions(V2, F) - 2 * S.P).norm(), 1e-12);
}

TEST(SpatialQuadric, SumOfSquaredPlaneDistancesAndMinimiser) {
  // Three orthogonal planes x = 1, y = −2, z = 3 (weights 1, 2, 3) meet at (1, −2, 3).
  mm::Quadric q;
  q.add_plane(1, 0, 0, 1.0, 1.0);
  q.add_plane(0, 1, 0, -2.0, 2.0);
  mm::Quadric r;
  r.add_plane(0, 0, 1, 3.0, 3.0);
  q.add(r);
  EXPECT_DOUBLE_EQ(q.area, 6.0);
  EXPECT_NEAR(q.eval(1, -2, 3), 0.0, 1e-12);
  // Q(p) = Σ w (n·p − d)²
  EXPECT_NEAR(q.eval(0, 0, 0), 1 * 1 + 2 * 4 + 3 * 9, 1e-12);
  EXPECT_NEAR(q.eval(2, 1, -1), 1 * 1 + 2 * 9 + 3 * 16, 1e-12);
  double p[3];
  ASSERT_TRUE(q.minimiser(p));
  EXPECT_NEAR(p[0], 1, 1e-12);
  EXPECT_NEAR(p[1], -2, 1e-12);
  EXPECT_NEAR(p[2], 3, 1e-12);
  // Parallel planes only (a rank-1 3x3 part): no unique minimiser.
  mm::Quadric flat;
  flat.add_plane(0, 0, 1, 0.0, 1.0);
  flat.add_plane(0, 0, 1, 1.0, 1.0);
  EXPECT_FALSE(flat.minimiser(p));
  EXPECT_NEAR(flat.eval(5, 7, 0.5), 0.5, 1e-12);
  EXPECT_FALSE(mm::Quadric().minimiser(p));
}

TEST(SpatialGrid, PointGridBoxQueriesMatchBruteForce) {
  Lcg rng;
  Eigen::MatrixXd P(2000, 3);
  for (int i = 0; i < P.rows(); ++i) P.row(i) << rng.next() * 4 - 1, rng.next(), rng.next() * 0.5;
  const mm::PointGrid grid(P);
  // 48 cells along the longest side (x), plus one for a point on the far end.
  EXPECT_GE(grid.grid().dims[0], 48);
  EXPECT_LE(grid.grid().dims[0], 49);
  for (int t = 0; t < 50; ++t) {
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      const double a = rng.next() * 5 - 1.5, b = rng.next() * 5 - 1.5;
      lo[k] = std::min(a, b) * (k == 0 ? 1.0 : 0.4);
      hi[k] = std::max(a, b) * (k == 0 ? 1.0 : 0.4);
    }
    std::vector<int> got, want;
    grid.for_each_in_box(lo, hi, [&](int i) {
      got.push_back(i);
      return true;
    });
    for (int i = 0; i < P.rows(); ++i)
      if (P(i, 0) >= lo[0] && P(i, 1) >= lo[1] && P(i, 2) >= lo[2] && P(i, 0) <= hi[0] && P(i, 1) <= hi[1] &&
          P(i, 2) <= hi[2])
        want.push_back(i);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want) << "query " << t;
  }
  // Early stop: the callback's false ends the query.
  int calls = 0;
  const double all_lo[3] = {-10, -10, -10}, all_hi[3] = {10, 10, 10};
  EXPECT_FALSE(grid.for_each_in_box(all_lo, all_hi, [&](int) { return ++calls < 5; }));
  EXPECT_EQ(calls, 5);
  EXPECT_TRUE(mm::PointGrid(Eigen::MatrixXd(0, 3)).for_each_in_box(all_lo, all_hi, [](int) { return false; }));
}

// The nearest point's squared distance equals Eigen's brute-force minimum bit for bit, for
// queries inside, outside and on the points (a flat set, coarse and fine grids).
TEST(SpatialGrid, PointGridNearestEqualsBruteForce) {
  Lcg rng;
  Eigen::MatrixXd P(1500, 3);
  for (int i = 0; i < P.rows(); ++i) P.row(i) << rng.next() * 3 - 1, rng.next(), i % 3 ? rng.next() * 0.5 : 0.25;
  for (int cells : {1, 9, 48}) {
    const mm::PointGrid grid(P, cells);
    for (int t = 0; t < 400; ++t) {
      Eigen::RowVector3d q;
      if (t % 4 == 0) q = P.row(t % P.rows());
      else q << rng.next() * 6 - 2.5, rng.next() * 2 - 0.5, rng.next() * 2 - 0.5;
      const double p[3] = {q[0], q[1], q[2]};
      EXPECT_EQ(grid.nearest_sq_distance(p), (P.rowwise() - q).rowwise().squaredNorm().minCoeff()) << cells << " " << t;
    }
  }
  const double p[3] = {0, 0, 0};
  EXPECT_EQ(mm::PointGrid(Eigen::MatrixXd(0, 3)).nearest_sq_distance(p), std::numeric_limits<double>::infinity());
}

TEST(SpatialGrid, BoxGridReportsEachEntryOnceAndRemovesIt) {
  mm::UniformGrid g;
  g.cell = 1;
  g.dims[0] = g.dims[1] = g.dims[2] = 4;  // [0, 4)³; outside coordinates clamp to the border
  EXPECT_EQ(g.coord(-3.0, 0), 0);
  EXPECT_EQ(g.coord(2.5, 1), 2);
  EXPECT_EQ(g.coord(9.0, 2), 3);
  mm::BoxGrid<int> bg;
  bg.reset(g);
  const auto r7 = bg.range(Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(1.5, 1.5, 0.5));  // cells (0..1, 0..1, 0)
  EXPECT_EQ(r7.lo[0], 0);
  EXPECT_EQ(r7.hi[0], 1);
  EXPECT_EQ(r7.hi[1], 1);
  EXPECT_EQ(r7.hi[2], 0);
  bg.insert(r7, 7);
  bg.insert(bg.range(Eigen::Vector3d(3.5, 3.5, 3.5), Eigen::Vector3d(9.0, 9.0, 9.0)), 9);  // cell (3, 3, 3)
  bg.insert(bg.range(Eigen::Vector3d(-1.0, 0.2, 0.2), Eigen::Vector3d(5.0, 0.3, 0.3)), 5);  // a row of 4 cells
  auto collect = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    std::vector<int> out;
    bg.for_each_in_box(lo, hi, [&](int e) {
      out.push_back(e);
      return true;
    });
    std::sort(out.begin(), out.end());
    return out;
  };
  // An entry filed under several cells is reported once, whichever of its cells the box covers.
  EXPECT_EQ(collect(Eigen::Vector3d(1.2, 0.1, 0.1), Eigen::Vector3d(1.3, 0.2, 0.2)), (std::vector<int>{5, 7}));
  EXPECT_EQ(collect(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 4, 4)), (std::vector<int>{5, 7, 9}));
  EXPECT_EQ(collect(Eigen::Vector3d(1.1, 1.1, 0.1), Eigen::Vector3d(3.9, 3.9, 0.1)), (std::vector<int>{7}));
  EXPECT_EQ(collect(Eigen::Vector3d(2.5, 0.5, 0.5), Eigen::Vector3d(3.5, 0.5, 0.5)), (std::vector<int>{5}));
  EXPECT_TRUE(collect(Eigen::Vector3d(2.1, 2.1, 2.1), Eigen::Vector3d(2.2, 2.2, 2.2)).empty());
  // The search stops at the first false.
  int calls = 0;
  EXPECT_FALSE(bg.for_each_in_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 4, 4), [&](int) { return ++calls < 2; }));
  EXPECT_EQ(calls, 2);
  // Removal takes the entry out of every cell it was filed under, and only that entry.
  bg.remove(r7, [](int e) { return e == 7; });
  EXPECT_EQ(collect(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 4, 4)), (std::vector<int>{5, 9}));
  EXPECT_EQ(collect(Eigen::Vector3d(1.1, 1.1, 0.1), Eigen::Vector3d(1.2, 1.2, 0.2)), std::vector<int>{});
}
