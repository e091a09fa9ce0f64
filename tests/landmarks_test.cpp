// Tests of core/spectral/landmarks: normalized indicator functions (support = the k-ring, unit
// A-weighted integral), the source ring count matching the reference region's normalized area
// (best k, areas within tolerance on same-shape and cat → lion pairs), farthest-point landmarks
// (distinct, first = farthest from vertex 0, the farthest-point covering property under the
// edge-length metric), and errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <set>
#include <vector>

#include "io/landmarks_file.h"
#include "mesh/topology.h"
#include "operators/operators.h"
#include "spectral/landmarks.h"
#include "test_support.h"

namespace {

std::vector<mm::LandmarkPair> load_pairs(const std::string& rel) {
  std::vector<mm::LandmarkPair> out;
  const mm::Status s = mm::io::read_landmarks(mm::test::data_path(rel), &out);
  EXPECT_TRUE(s.ok()) << s.message;
  return out;
}

double region_area(const std::vector<int>& region, const Eigen::VectorXd& mass) {
  double a = 0;
  for (int v : region) a += mass[v];
  return a;
}

// Edge-length (Dijkstra) distance from `sources` (minimum over them) on the vertex graph.
std::vector<double> graph_distance(const Eigen::MatrixXd& V, const std::vector<std::vector<int>>& adj,
                                   const std::vector<int>& sources) {
  std::vector<double> d(V.rows(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  for (int s : sources) {
    d[s] = 0;
    q.push({0.0, s});
  }
  while (!q.empty()) {
    const auto [dv, v] = q.top();
    q.pop();
    if (dv > d[v]) continue;
    for (int w : adj[v]) {
      const double nd = dv + (V.row(v) - V.row(w)).norm();
      if (nd < d[w]) {
        d[w] = nd;
        q.push({nd, w});
      }
    }
  }
  return d;
}

// Checks the functions of `pairs` between (Fr, mr) and (Fs, ms): supports, values, integrals,
// and that the chosen source k is the best in 1..max_source_rings. Returns the largest
// relative differences |a_s − a_r| / a_r of normalized region areas, sorted ascending.
std::vector<double> check_functions(const mm::LandmarkFunctions& lf, const Eigen::MatrixXi& Fr, const Eigen::VectorXd& mr,
                       const Eigen::MatrixXi& Fs, const Eigen::VectorXd& ms,
                       const std::vector<mm::LandmarkPair>& pairs, const mm::LandmarkOptions& opt) {
  const auto adj_r = mm::vertex_adjacency(Fr, static_cast<int>(mr.size()));
  const auto adj_s = mm::vertex_adjacency(Fs, static_cast<int>(ms.size()));
  EXPECT_EQ(lf.reference.cols(), static_cast<Eigen::Index>(pairs.size()));
  EXPECT_EQ(lf.source.cols(), static_cast<Eigen::Index>(pairs.size()));
  std::vector<double> mismatch;
  for (size_t j = 0; j < pairs.size(); ++j) {
    const Eigen::Index c = static_cast<Eigen::Index>(j);
    // Unit A-weighted integral: ⟨1, f⟩_A = Σ m_v f_v = 1 on both meshes.
    EXPECT_NEAR(mr.dot(lf.reference.col(c)), 1.0, 1e-12) << "pair " << j;
    EXPECT_NEAR(ms.dot(lf.source.col(c)), 1.0, 1e-12) << "pair " << j;
    // Support: exactly the k-ring, constant 1/area there.
    const std::vector<int> rr = mm::k_ring(adj_r, pairs[j].reference, opt.reference_rings);
    const std::vector<int> rs = mm::k_ring(adj_s, pairs[j].source, lf.source_rings[j]);
    const double ar = region_area(rr, mr), as = region_area(rs, ms);
    EXPECT_EQ((lf.reference.col(c).array() != 0).count(), static_cast<Eigen::Index>(rr.size())) << "pair " << j;
    EXPECT_EQ((lf.source.col(c).array() != 0).count(), static_cast<Eigen::Index>(rs.size())) << "pair " << j;
    for (int v : rr) EXPECT_DOUBLE_EQ(lf.reference(v, c), 1.0 / ar);
    for (int v : rs) EXPECT_DOUBLE_EQ(lf.source(v, c), 1.0 / as);
    // The chosen k is the best match of normalized areas.
    const double target = ar / mr.sum();
    const double chosen = std::abs(as / ms.sum() - target);
    for (int k = 1; k <= opt.max_source_rings; ++k)
      EXPECT_LE(chosen, std::abs(region_area(mm::k_ring(adj_s, pairs[j].source, k), ms) / ms.sum() - target))
          << "pair " << j << ", k = " << k << " matches better than the chosen " << lf.source_rings[j];
    mismatch.push_back(chosen / target);
  }
  std::sort(mismatch.begin(), mismatch.end());
  return mismatch;
}

}  // namespace

using namespace mm;

TEST(Landmarks, SameShapeRegionsMatchAndIndicatorsIntegrateToOne) {
  // cat-reference and cat-05 share connectivity; the pose changes areas only a little, so the
  // source keeps k = 3 almost everywhere and region areas agree closely.
  const Mesh a = test::load_mesh("pose/cat-reference.ply");
  const Mesh b = test::load_mesh("pose/cat-05.ply");
  ASSERT_EQ(a.F.rows(), b.F.rows());
  const Eigen::VectorXd ma = mass_diagonal(a.V, a.F), mb = mass_diagonal(b.V, b.F);
  std::vector<LandmarkPair> pairs;
  for (int v : farthest_point_landmarks(a.V, a.F, 30)) pairs.push_back({v, v});
  const LandmarkOptions opt;
  const LandmarkFunctions lf = landmark_functions(a.F, ma, b.F, mb, pairs, opt);
  ASSERT_TRUE(lf.status.ok()) << lf.status.message;
  const std::vector<double> m = check_functions(lf, a.F, ma, b.F, mb, pairs, opt);
  int same_k = 0;
  for (int k : lf.source_rings) same_k += k == opt.reference_rings;
  std::printf("[ landmarks ] cat-05: %d of %zu keep k = 3; relative area mismatch:", same_k, pairs.size());
  for (double x : m) std::printf(" %.3f", x);
  std::printf("\n");
  EXPECT_GE(same_k, 25);
  // Rings are discrete (the area jumps from one k to the next), so single pairs can be off by
  // a ring step; most match closely.
  EXPECT_LE(m[m.size() / 2], 0.1) << "median";
  EXPECT_LE(m[2 * m.size() / 3], 0.1) << "two thirds";
}

TEST(Landmarks, CatToLionRegionAreasMatchWithinTolerance) {
  const Mesh cat = test::load_mesh("pose/cat-reference.ply");
  const Mesh lion = test::load_mesh("pose/lion-reference.ply");
  const auto pairs = load_pairs("landmarks/cat-lion.json");
  ASSERT_GE(pairs.size(), 25u);
  const Eigen::VectorXd mc = mass_diagonal(cat.V, cat.F), ml = mass_diagonal(lion.V, lion.F);
  const LandmarkOptions opt;
  const LandmarkFunctions lf = landmark_functions(cat.F, mc, lion.F, ml, pairs, opt);
  ASSERT_TRUE(lf.status.ok()) << lf.status.message;
  const std::vector<double> m = check_functions(lf, cat.F, mc, lion.F, ml, pairs, opt);
  std::printf("[ landmarks ] cat-lion: relative area mismatch:");
  for (double x : m) std::printf(" %.3f", x);
  std::printf("\n");
  // Different meshes: the lion is coarser, so a few of its 1-rings are already larger than the
  // cat's 3-rings; still most regions match within a quarter.
  EXPECT_LE(m[m.size() / 2], 0.25) << "median";
}

TEST(Landmarks, FarthestPointLandmarksAreDistinctAndCoverTheSurface) {
  const Mesh cat = test::load_mesh("pose/cat-reference.ply");
  const int n = static_cast<int>(cat.V.rows());
  const auto adj = vertex_adjacency(cat.F, n);
  const std::vector<int> L = farthest_point_landmarks(cat.V, cat.F, 30);
  ASSERT_EQ(L.size(), 30u);
  EXPECT_EQ(std::set<int>(L.begin(), L.end()).size(), L.size()) << "repeated landmark";
  // The first is the vertex farthest (edge-length metric) from vertex 0.
  const std::vector<double> d0 = graph_distance(cat.V, adj, {0});
  double far = 0;
  for (double d : d0)
    if (std::isfinite(d)) far = std::max(far, d);
  EXPECT_DOUBLE_EQ(d0[L[0]], far);
  // Farthest-point property: every landmark is at least the covering radius (largest distance
  // from a vertex to its nearest landmark) from the others.
  const std::vector<double> cover = graph_distance(cat.V, adj, L);
  double radius = 0;
  for (double d : cover)
    if (std::isfinite(d)) radius = std::max(radius, d);
  double closest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < L.size(); ++i) {
    std::vector<int> others = L;
    others.erase(others.begin() + static_cast<long>(i));
    closest = std::min(closest, graph_distance(cat.V, adj, others)[L[i]]);
  }
  EXPECT_GT(radius, 0);
  EXPECT_GE(closest, radius * (1 - 1e-12));
  // Spread: 30 landmarks cover the cat far better than one does.
  EXPECT_LT(radius, 0.35 * far);
  // Edge cases: no landmarks asked, or more than there are vertices.
  EXPECT_TRUE(farthest_point_landmarks(cat.V, cat.F, 0).empty());
  Eigen::MatrixXd Vt(4, 3);
  Vt << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Eigen::MatrixXi Ft(4, 3);
  Ft << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  const std::vector<int> all = farthest_point_landmarks(Vt, Ft, 10);
  EXPECT_EQ(std::set<int>(all.begin(), all.end()).size(), 4u);
}

TEST(Landmarks, ZeroAreaRegionAndBadPairsGiveClearStatus) {
  const Mesh cat = test::load_mesh("pose/cat-reference.ply");
  const Eigen::VectorXd mc = mass_diagonal(cat.V, cat.F);
  std::vector<LandmarkPair> pairs;
  for (int v : farthest_point_landmarks(cat.V, cat.F, 8)) pairs.push_back({v, v});
  Eigen::VectorXd zero = mc;
  for (int v : k_ring(vertex_adjacency(cat.F, static_cast<int>(mc.size())), pairs[2].reference, 3)) zero[v] = 0;
  const LandmarkFunctions z = landmark_functions(cat.F, zero, cat.F, mc, pairs);
  EXPECT_EQ(z.status.code, StatusCode::InvalidMesh);
  EXPECT_NE(z.status.message.find("landmark pair 2"), std::string::npos) << z.status.message;
  std::vector<LandmarkPair> few(pairs.begin(), pairs.begin() + 5);
  EXPECT_EQ(landmark_functions(cat.F, mc, cat.F, mc, few).status.code, StatusCode::InvalidArgument);
  pairs[4].source = static_cast<int>(mc.size());
  EXPECT_EQ(landmark_functions(cat.F, mc, cat.F, mc, pairs).status.code, StatusCode::InvalidArgument);
}
