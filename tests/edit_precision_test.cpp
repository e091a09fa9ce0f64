// Precision of the editing session (core/edit, paper 001) on real meshes: the identity and a
// similarity applied to every constraint must come back to ≤ 1e-9 of the bounding-box diagonal,
// after the stage-1 solve (Eq. 7: drag with the handle basis, and drag_positions with
// back-substitutions) and after finalize (Eq. 9/10). The meshes have thin parts (legs, tails,
// fingers) and near-degenerate vertices (Sec. 3.3) injected here, and are solved with few, small
// constraints far apart: the badly conditioned case where the normal equations AᵀA (condition
// number squared) lost up to 1e-6 of the diagonal before the solves were refined against the
// unsquared system (issue 11, "Precision first").
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "edit/laplacian_editor.h"
#include "edit_test_util.h"
#include "mesh/mesh.h"
#include "mesh/topology.h"

namespace {

using namespace mm;
using namespace mm::edit_test;

constexpr double kTolerance = 1e-9;  // of the bounding-box diagonal

struct PrecisionCase {
  std::string name;
  Mesh mesh;
  std::vector<int> h1, h2, fixed;  // two small handles far apart, a small fixed patch
  std::vector<int> degenerate;     // vertices made near-degenerate here
};

// Flattens the 1-ring of `count` vertices spread over the mesh (indices evenly spaced, at least
// four rings apart and away from `avoid`) towards its least-squares plane, keeping 1e-3 of the
// out-of-plane offsets: the center's cond(V_i V_iᵀ) grows by ~1e6, above the paper's 2e5
// threshold (Sec. 3.3) but below the 1e12 at which the editor gives up, so the same mesh also
// runs with degenerate handling switched off.
std::vector<int> inject_degenerate(Mesh* m, int count, const std::vector<char>& avoid) {
  const int n = m->num_vertices();
  const auto adj = vertex_adjacency(m->F, n);
  std::vector<char> blocked = avoid;
  std::vector<int> out;
  for (int k = 0; k < count; ++k) {
    for (int v = (k + 1) * n / (count + 1); v < n; ++v) {
      if (blocked[v] || adj[v].size() < 4) continue;
      std::vector<int> ring = adj[v];
      ring.push_back(v);
      Eigen::MatrixXd P(ring.size(), 3);
      for (size_t i = 0; i < ring.size(); ++i) P.row(static_cast<Eigen::Index>(i)) = m->V.row(ring[i]);
      const Eigen::RowVector3d c = P.colwise().mean();
      const Eigen::MatrixXd Q = P.rowwise() - c;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(Q.transpose() * Q);
      const Eigen::RowVector3d normal = es.eigenvectors().col(0).transpose();
      for (int w : ring) {
        const double d = (m->V.row(w) - c).dot(normal);
        m->V.row(w) -= (1.0 - 1e-3) * d * normal;
      }
      for (int w : k_ring(adj, v, 4)) blocked[w] = 1;
      out.push_back(v);
      break;
    }
  }
  return out;
}

// Vertices of the faces at non-manifold edges and vertices: constrained, so that the edited
// region is manifold (camel_ref has 26 such edges).
std::vector<int> non_manifold_neighbourhood(const Mesh& m) {
  std::vector<char> bad(m.num_vertices(), 0);
  for (const EdgeUse& e : edge_uses(m.F))
    if (e.faces > 2) bad[e.i] = bad[e.j] = 1;
  for (const VertexFans& v : non_manifold_vertices(m.F, m.num_vertices())) bad[v.vertex] = 1;
  std::vector<char> mark(m.num_vertices(), 0);
  for (int f = 0; f < m.F.rows(); ++f)
    if (bad[m.F(f, 0)] || bad[m.F(f, 1)] || bad[m.F(f, 2)])
      for (int c = 0; c < 3; ++c) mark[m.F(f, c)] = 1;
  std::vector<int> out;
  for (int v = 0; v < m.num_vertices(); ++v)
    if (mark[v]) out.push_back(v);
  return out;
}

int extreme_vertex(const Eigen::MatrixXd& V, const Eigen::Vector3d& dir) {
  Eigen::Index i;
  (V * dir).maxCoeff(&i);
  return static_cast<int>(i);
}

PrecisionCase precision_case(const std::string& file, int subdivisions) {
  PrecisionCase c;
  c.name = file + (subdivisions ? " (subdivided)" : "");
  c.mesh = load(file);
  for (int k = 0; k < subdivisions; ++k) c.mesh = midpoint_subdivide(c.mesh);
  const Eigen::MatrixXd& V = c.mesh.V;
  const int n = c.mesh.num_vertices();
  const auto adj = vertex_adjacency(c.mesh.F, n);
  const int ax = long_axis(V);
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  e[ax] = 1;
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  up[(ax + 1) % 3] = 1;
  // Two small handles (2-rings) at the two ends of the long axis, a small fixed patch at the top.
  c.h1 = k_ring(adj, extreme_vertex(V, e), 2);
  c.h2 = k_ring(adj, extreme_vertex(V, -e), 2);
  std::vector<char> taken(n, 0);
  for (int v : c.h1) taken[v] = 1;
  for (int v : c.h2) taken[v] = 1;
  for (int v : k_ring(adj, extreme_vertex(V, up), 2))
    if (!taken[v]) c.fixed.push_back(v), taken[v] = 1;
  for (int v : non_manifold_neighbourhood(c.mesh))
    if (!taken[v]) c.fixed.push_back(v), taken[v] = 1;
  std::vector<char> avoid(n, 0);
  for (int v = 0; v < n; ++v)
    if (taken[v]) avoid[v] = 1;
  for (int v : k_ring(adj, [&] {
         std::vector<int> s;
         for (int w = 0; w < n; ++w)
           if (taken[w]) s.push_back(w);
         return s;
       }(), 3))
    avoid[v] = 1;
  c.degenerate = inject_degenerate(&c.mesh, 6, avoid);
  return c;
}

Eigen::MatrixXd apply_all(const HandleTransform& T, const Eigen::MatrixXd& V) {
  Eigen::MatrixXd out(V.rows(), 3);
  for (int i = 0; i < V.rows(); ++i) out.row(i) = T.apply(V.row(i).transpose()).transpose();
  return out;
}

// Max vertex error relative to the bounding-box diagonal of the rest mesh.
double relative_error(const EditResult& r, const Eigen::MatrixXd& expected, double diag) {
  EXPECT_TRUE(r.status.ok()) << r.status.message;
  if (!r.status.ok() || r.V.rows() != expected.rows()) return 1.0;
  return (r.V - expected).cwiseAbs().maxCoeff() / diag;
}

void report(const std::string& what, double err) {
  std::cout << "[ precision ] " << what << ": " << err << "\n";
  ::testing::Test::RecordProperty(what, std::to_string(err));
}

// (a) Identity on two small handles far apart + a fixed patch: drag (basis), drag_positions,
// finalize in both modes. With degenerate handling on, and (first mesh) off.
void check_identity(const PrecisionCase& c, double condition_threshold) {
  const Eigen::MatrixXd& V = c.mesh.V;
  const double diag = bounding_box_diagonal(V);
  EditRegion region;
  region.handles = {c.h1, c.h2};
  region.fixed = c.fixed;
  LaplacianEditOptions opt;
  opt.condition_threshold = condition_threshold;
  LaplacianEditor ed;
  const Status s = ed.precompute(V, c.mesh.F, region, opt);
  ASSERT_TRUE(s.ok()) << s.message;
  if (condition_threshold < 1e10) {
    EXPECT_GE(ed.stats().degenerate_vertices, static_cast<int>(c.degenerate.size())) << c.name;
  }
  const std::string tag = c.name + (condition_threshold < 1e10 ? "" : " (degenerate handling off)");
  const double drag = relative_error(ed.drag({HandleTransform{}, HandleTransform{}}), V, diag);
  report(tag + " identity drag", drag);
  EXPECT_LE(drag, kTolerance) << tag;
  for (FeatureSize mode : {FeatureSize::Keep, FeatureSize::Scale}) {
    const double fin = relative_error(ed.finalize(mode), V, diag);
    report(tag + " identity finalize " + (mode == FeatureSize::Keep ? "Eq. 9" : "Eq. 10"), fin);
    EXPECT_LE(fin, kTolerance) << tag;
  }
  const double pos = relative_error(ed.drag_positions(V), V, diag);
  report(tag + " identity drag_positions", pos);
  EXPECT_LE(pos, kTolerance) << tag;
  const double fin = relative_error(ed.finalize(FeatureSize::Keep), V, diag);
  report(tag + " identity drag_positions + finalize", fin);
  EXPECT_LE(fin, kTolerance) << tag;
}

// (b) A similarity on all constraints (both handles and the fixed patch, as a third handle):
// rotation about an oblique axis, translation, uniform scale 0.37 and 2.6, features scaled
// (Eq. 10). The exact solution of both stages is the transformed mesh.
// With soft_weight > 0 the constraints are soft (least-squares rows in both stages, whose finalize
// system is then a normal-equations system too).
void check_similarity(const PrecisionCase& c, double soft_weight = 0) {
  const Eigen::MatrixXd& V = c.mesh.V;
  const double diag = bounding_box_diagonal(V);
  EditRegion region;
  region.handles = {c.h1, c.h2, c.fixed};
  LaplacianEditOptions opt;
  opt.soft_constraint_weight = soft_weight;
  LaplacianEditor ed;
  const Status s = ed.precompute(V, c.mesh.F, region, opt);
  ASSERT_TRUE(s.ok()) << s.message;
  EXPECT_GE(ed.stats().degenerate_vertices, static_cast<int>(c.degenerate.size())) << c.name;
  const Eigen::Vector3d pivot = V.colwise().mean().transpose() + Eigen::Vector3d(0.1, -0.2, 0.05) * diag;
  for (double scale : {0.37, 2.6}) {
    const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0.3, -0.2, 0.5) * diag,
                                                          Eigen::Vector3d(1, 2, 3), 2.0, pivot, scale);
    const Eigen::MatrixXd expected = apply_all(T, V);
    const std::string tag = c.name + (soft_weight > 0 ? " soft" : "") + " similarity s=" + std::to_string(scale).substr(0, 4);
    const double drag = relative_error(ed.drag({T, T, T}), expected, diag);
    report(tag + " drag", drag);
    EXPECT_LE(drag, kTolerance) << tag;
    const double fin = relative_error(ed.finalize(FeatureSize::Scale), expected, diag);
    report(tag + " finalize Eq. 10", fin);
    EXPECT_LE(fin, kTolerance) << tag;
    const double pos = relative_error(ed.drag_positions(expected), expected, diag);
    report(tag + " drag_positions", pos);
    EXPECT_LE(pos, kTolerance) << tag;
    const double fin2 = relative_error(ed.finalize(FeatureSize::Scale), expected, diag);
    report(tag + " drag_positions + finalize Eq. 10", fin2);
    EXPECT_LE(fin2, kTolerance) << tag;
    // The interactive preview: one plain normal-equations solve, no refinement — off by
    // ~eps·cond(A)², as an LᵀL drag would be; refining (above) removes it.
    const EditResult q = ed.drag_positions(expected, 0);
    EXPECT_EQ(q.refinements, 0) << tag;
    const double prev = relative_error(q, expected, diag);
    report(tag + " drag_positions preview (1 solve)", prev);
    EXPECT_LE(prev, 1e-4) << tag;
    EXPECT_GT(prev, pos) << tag << ": the refinement should have had something to remove";
  }
}

// Camel (21.9k vertices, thin legs, non-manifold edges kept constrained).
TEST(EditPrecision, CamelIdentityAndSimilarity) {
  const PrecisionCase c = precision_case("pose/camel_ref.ply", 0);
  ASSERT_EQ(c.degenerate.size(), 6u);
  check_identity(c, 2e5);
  check_identity(c, 1e300);
  check_similarity(c);
}

// Horse (19.2k vertices, thin legs and tail).
TEST(EditPrecision, HorseIdentityAndSimilarity) {
  const PrecisionCase c = precision_case("pose/horse0.ply", 0);
  ASSERT_EQ(c.degenerate.size(), 6u);
  check_identity(c, 2e5);
  check_similarity(c);
  check_similarity(c, 10.0);  // soft constraints (before refinement: finalize off by ~1e-4)
}

// Cat, midpoint-subdivided once (7.2k → 28.8k vertices, thin legs and tail; the edge midpoints
// lie in their faces' planes, so flat parts of the body add degenerate vertices of their own).
TEST(EditPrecision, SubdividedCatIdentityAndSimilarity) {
  const PrecisionCase c = precision_case("pose/cat-reference.ply", 1);
  ASSERT_EQ(c.degenerate.size(), 6u);
  check_identity(c, 2e5);
  check_similarity(c);
}

}  // namespace

