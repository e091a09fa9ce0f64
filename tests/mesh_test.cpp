// Validation, topology and welding: each defect class on a tiny hand-made mesh, then real
// meshes from data/.
#include <gtest/gtest.h>

#include <limits>
#include <map>

#include "io/asset.h"
#include "mesh/midpoint_subdivide.h"
#include "mesh/topology.h"
#include "mesh/validate.h"
#include "mesh/weld.h"
#include "test_meshes.h"
#include "test_support.h"

namespace mm {

namespace {

// Two triangles sharing edge 1-2, a unit square split along its diagonal:
//   3---2
//   | / |
//   0---1
Eigen::MatrixXd square_V() {
  Eigen::MatrixXd V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  return V;
}
Eigen::MatrixXi square_F() {
  Eigen::MatrixXi F(2, 3);
  F << 0, 1, 2, 0, 2, 3;
  return F;
}

const DefectReport* find_defect(const MeshReport& r, MeshDefect d) {
  for (const auto& x : r.defects)
    if (x.defect == d) return &x;
  return nullptr;
}

}  // namespace

TEST(Validate, CleanSquareHasNoDefectsAndOneBoundaryLoop) {
  const MeshReport r = validate_mesh(square_V(), square_F());
  EXPECT_TRUE(r.defects.empty()) << r.to_text();
  EXPECT_EQ(r.num_components, 1);
  ASSERT_EQ(r.boundary_loops.size(), 1u);
  EXPECT_EQ(r.boundary_loops[0], (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(r.euler_characteristic, 1);
  EXPECT_NEAR(r.bbox_diagonal, std::sqrt(2.0), 1e-15);
}

TEST(Validate, EmptyMesh) {
  const MeshReport r = validate_mesh(Eigen::MatrixXd(0, 3), Eigen::MatrixXi(0, 3));
  ASSERT_NE(find_defect(r, MeshDefect::Empty), nullptr);
  const Status s = r.status(fatal_defects());
  EXPECT_EQ(s.code, StatusCode::InvalidMesh);
  EXPECT_NE(s.message.find("empty"), std::string::npos);
}

TEST(Validate, NonFiniteCoordinates) {
  Eigen::MatrixXd V = square_V();
  V(2, 1) = std::numeric_limits<double>::quiet_NaN();
  V(3, 0) = std::numeric_limits<double>::infinity();
  const MeshReport r = validate_mesh(V, square_F());
  const auto* d = find_defect(r, MeshDefect::NonFiniteCoordinate);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 2);
  EXPECT_EQ(d->example, "vertex 2");
  EXPECT_EQ(r.status(fatal_defects()).code, StatusCode::InvalidMesh);
  EXPECT_TRUE(std::isfinite(r.bbox_diagonal));
}

TEST(Validate, OutOfRangeIndices) {
  Eigen::MatrixXi F = square_F();
  F(1, 2) = 7;
  const MeshReport r = validate_mesh(square_V(), F);
  const auto* d = find_defect(r, MeshDefect::IndexOutOfRange);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 1);
  EXPECT_NE(d->example.find("face 1"), std::string::npos);
  EXPECT_NE(r.status(fatal_defects()).message.find("out-of-range"), std::string::npos);
}

TEST(Validate, DegenerateFacesRepeatedIndexAndZeroArea) {
  Eigen::MatrixXd V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0;  // vertex 4 collinear with 0 and 1
  Eigen::MatrixXi F(4, 3);
  F << 0, 1, 2, 0, 2, 3, 0, 0, 3, 0, 1, 4;
  const MeshReport r = validate_mesh(V, F);
  const auto* d = find_defect(r, MeshDefect::DegenerateFace);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 2);
  EXPECT_NE(d->example.find("face 2"), std::string::npos);
  EXPECT_TRUE(r.status(fatal_defects()).ok());
  EXPECT_FALSE(r.status(manifold_defects()).ok());
}

TEST(Validate, DuplicateFacesInAnyOrder) {
  Eigen::MatrixXi F(3, 3);
  F << 0, 1, 2, 0, 2, 3, 2, 0, 1;
  const MeshReport r = validate_mesh(square_V(), F);
  const auto* d = find_defect(r, MeshDefect::DuplicateFace);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 1);
  EXPECT_NE(d->example.find("repeats face 0"), std::string::npos);
}

TEST(Validate, NonManifoldEdge) {
  // Three triangles on edge 0-1 (a "book" with three pages).
  Eigen::MatrixXd V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0, 0.5, 0, 1;
  Eigen::MatrixXi F(3, 3);
  F << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  const MeshReport r = validate_mesh(V, F);
  const auto* d = find_defect(r, MeshDefect::NonManifoldEdge);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 1);
  EXPECT_EQ(d->example, "edge 0-1 in 3 faces");
  EXPECT_NE(r.status(manifold_defects()).message.find("1 non-manifold edges"), std::string::npos);
}

TEST(Validate, NonManifoldVertexBowTie) {
  // Two triangles touching only at vertex 0.
  Eigen::MatrixXd V(5, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
  Eigen::MatrixXi F(2, 3);
  F << 0, 1, 2, 0, 3, 4;
  const MeshReport r = validate_mesh(V, F);
  const auto* d = find_defect(r, MeshDefect::NonManifoldVertex);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 1);
  EXPECT_EQ(d->example, "vertex 0 joins 2 fans");
  EXPECT_EQ(r.num_components, 1);
}

TEST(Validate, UnreferencedVertex) {
  Eigen::MatrixXd V(5, 3);
  V.topRows(4) = square_V();
  V.row(4) << 5, 5, 5;
  const MeshReport r = validate_mesh(V, square_F());
  const auto* d = find_defect(r, MeshDefect::UnreferencedVertex);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->example, "vertex 4");
  EXPECT_EQ(r.num_components, 1);  // the lone vertex is not a surface component
}

TEST(Validate, InconsistentOrientation) {
  // Face 1 reversed to (0, 3, 2): both faces now contain the directed edge 2->0.
  Eigen::MatrixXi F = square_F();
  F.row(1) << 0, 3, 2;
  const MeshReport r = validate_mesh(square_V(), F);
  const auto* d = find_defect(r, MeshDefect::InconsistentOrientation);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 1);
  EXPECT_EQ(d->example, "edge 2->0 appears twice");
}

TEST(Topology, KRingGrowsByRings) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::grid(5, 5, &V, &F);
  const auto adj = vertex_adjacency(F, 25);
  EXPECT_EQ(k_ring(adj, 12, 0), std::vector<int>{12});
  EXPECT_EQ(k_ring(adj, 12, 1).size(), 7u);  // centre + 6 neighbours (diagonal split grid)
  EXPECT_EQ(k_ring(adj, 12, 2).size(), 19u);
  EXPECT_EQ(k_ring(adj, 12, 10).size(), 25u);
}

TEST(Topology, ComponentsOfTwoSpheres) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(1, &V, &F);
  Eigen::MatrixXd V2(V.rows() * 2, 3);
  V2 << V, V.rowwise() + Eigen::RowVector3d(3, 0, 0);
  Eigen::MatrixXi F2(F.rows() * 2, 3);
  F2 << F, F.array() + static_cast<int>(V.rows());
  int count = 0;
  const Eigen::VectorXi comp = vertex_components(F2, static_cast<int>(V2.rows()), &count);
  EXPECT_EQ(count, 2);
  EXPECT_EQ(comp[0], 0);
  EXPECT_EQ(comp[V.rows()], 1);
  const MeshReport r = validate_mesh(V2, F2);
  EXPECT_EQ(r.num_components, 2);
  EXPECT_TRUE(r.closed());
  EXPECT_EQ(r.euler_characteristic, 4);
}

TEST(Weld, MergesSeamSplitVerticesAndMapsBack) {
  // The square with vertices 0 and 2 duplicated for face 1 (as a glTF UV seam would).
  Eigen::MatrixXd V(6, 3);
  V << square_V(), 0, 0, 0, 1, 1, 0;
  Eigen::MatrixXi F(2, 3);
  F << 0, 1, 2, 4, 5, 3;
  const WeldResult w = weld_vertices(V, F);
  EXPECT_EQ(w.V.rows(), 4);
  EXPECT_EQ(w.F.rows(), 2);
  EXPECT_EQ(w.to_welded[4], 0);
  EXPECT_EQ(w.to_welded[5], 2);
  EXPECT_TRUE(validate_mesh(w.V, w.F).defects.empty());
  EXPECT_EQ(validate_mesh(w.V, w.F).boundary_loops.size(), 1u);
  const Eigen::MatrixXd back = unweld(w.V, w.to_welded);
  EXPECT_EQ((back - V).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Weld, AlreadyWeldedMeshIsUnchangedAndNaNIsNotMerged) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(2, &V, &F);
  const WeldResult w = weld_vertices(V, F);
  EXPECT_EQ(w.V, V);
  EXPECT_EQ(w.F, F);
  Eigen::MatrixXd Vn = square_V();
  Vn(1, 0) = std::numeric_limits<double>::quiet_NaN();
  Vn(3, 0) = std::numeric_limits<double>::quiet_NaN();
  const WeldResult wn = weld_vertices(Vn, square_F());
  EXPECT_EQ(wn.V.rows(), 4);
}

TEST(TopologyRealMesh, OpenMeshesHaveTheirDocumentedBoundaryLoops) {
  struct Case {
    const char* file;
    std::vector<size_t> loop_lengths;
  };
  // Loop lengths from data/MANIFEST.md (cylinder: 2 loops × 40, hand wrist: 16).
  for (const Case& c : {Case{"edit/cylinder_coarse.ply", {40, 40}}, Case{"edit/hand_lowres.ply", {16}},
                        Case{"edit/camelhead.ply", {56}}, Case{"edit/mannequin.ply", {60}}}) {
    const io::LoadResult lr = io::load_asset(test::data_path(c.file));
    ASSERT_TRUE(lr.status.ok()) << lr.status.message;
    const Mesh m = lr.asset.mesh();
    const MeshReport r = validate_mesh(m.V, m.F);
    EXPECT_TRUE(r.defects.empty()) << c.file << "\n" << r.to_text();
    std::vector<size_t> lengths;
    for (const auto& l : r.boundary_loops) lengths.push_back(l.size());
    EXPECT_EQ(lengths, c.loop_lengths) << c.file;
    EXPECT_EQ(r.num_components, 1) << c.file;
  }
}

TEST(TopologyRealMesh, CamelReportsItsKnownDefects) {
  const io::LoadResult lr = io::load_asset(test::data_path("pose/camel_ref.ply"));
  ASSERT_TRUE(lr.status.ok()) << lr.status.message;
  const MeshReport r = validate_mesh(lr.asset.V_raw, lr.asset.F_raw);
  // MANIFEST.md: 26 non-manifold edges, 5 boundary edges, 51 inconsistently oriented half-edges.
  EXPECT_EQ(r.count(MeshDefect::NonManifoldEdge), 26);
  EXPECT_GT(r.count(MeshDefect::InconsistentOrientation), 0);
  const Status s = r.status(manifold_defects());
  EXPECT_EQ(s.code, StatusCode::InvalidMesh);
  EXPECT_NE(s.message.find("26 non-manifold edges"), std::string::npos) << s.message;
}

TEST(TopologyRealMesh, ClosedMeshesAreWatertightWithExpectedGenus) {
  struct Case {
    const char* file;
    int euler;
  };
  for (const Case& c : {Case{"pose/cat-reference.ply", 2}, Case{"edit/skull.ply", -2},
                        Case{"pose/horse0.ply", 2}, Case{"edit/armadillo.ply", 2}}) {
    const io::LoadResult lr = io::load_asset(test::data_path(c.file));
    ASSERT_TRUE(lr.status.ok()) << lr.status.message;
    const Mesh m = lr.asset.mesh();
    const MeshReport r = validate_mesh(m.V, m.F);
    EXPECT_TRUE(r.closed()) << c.file;
    EXPECT_EQ(r.euler_characteristic, c.euler) << c.file;
    EXPECT_TRUE(r.status(manifold_defects()).ok()) << c.file << ": " << r.to_text();
  }
}

// validate_mesh finds edges, boundary loops, non-manifold edges and vertices and orientation
// flips in one pass over the corners around each vertex; the separate topology functions find
// them each on their own. Both must agree on meshes with every kind of defect.
TEST(Validate, OnePassTopologyAgreesWithTheSeparateFunctions) {
  std::vector<std::pair<Eigen::MatrixXd, Eigen::MatrixXi>> meshes;
  for (const char* file : {"pose/camel_ref.ply", "edit/hand_lowres.ply", "edit/cylinder_coarse.ply",
                           "anim/Fox/glTF-Binary/Fox.glb", "anim/KayKit/Knight.glb"}) {
    const io::LoadResult lr = io::load_asset(test::data_path(file));
    ASSERT_TRUE(lr.status.ok()) << file << ": " << lr.status.message;
    meshes.push_back({lr.asset.V_raw, lr.asset.F_raw});  // raw: seams, parts, open boundaries
  }
  {  // every defect at once: a fin (edge in 3 faces), a bow tie, a duplicate, a flipped face,
     // a repeated index and an out-of-range index
    Eigen::MatrixXd V;
    Eigen::MatrixXi F;
    test::grid(5, 4, &V, &F);
    const int n = static_cast<int>(V.rows());
    V.conservativeResize(n + 3, 3);
    V.row(n) << 0.5, 0.5, 1;
    V.row(n + 1) << 9, 9, 0;
    V.row(n + 2) << 9, 10, 0;
    Eigen::MatrixXi extra(6, 3);
    extra << F(0, 0), F(0, 2), n, F(3, 0), n + 1, n + 2, F(5, 0), F(5, 1), F(5, 2), F(7, 0), F(7, 2), F(7, 1),
        1, 1, 2, 0, 1, n + 7;
    F.conservativeResize(F.rows() + 6, 3);
    F.bottomRows(6) = extra;
    meshes.push_back({V, F});
  }
  for (const auto& [V, F] : meshes) {
    const int n = static_cast<int>(V.rows());
    Eigen::MatrixXi Fv(F.rows(), 3);
    int rows = 0;
    for (int f = 0; f < F.rows(); ++f) {
      const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
      if (a >= 0 && b >= 0 && c >= 0 && a < n && b < n && c < n && a != b && b != c && a != c) Fv.row(rows++) = F.row(f);
    }
    Fv.conservativeResize(rows, 3);
    const MeshReport r = validate_mesh(V, F);
    const std::vector<EdgeUse> edges = edge_uses(Fv);
    int fins = 0;
    for (const EdgeUse& e : edges) fins += e.faces > 2;
    EXPECT_EQ(r.num_edges, static_cast<int>(edges.size()));
    EXPECT_EQ(r.count(MeshDefect::NonManifoldEdge), fins);
    EXPECT_EQ(r.boundary_loops, boundary_loops(Fv, n));
    EXPECT_EQ(r.count(MeshDefect::NonManifoldVertex), static_cast<int>(non_manifold_vertices(Fv, n).size()));
    // The adjacency-slot counts (no sorting of edges) against edge_uses, and the boundary flags.
    const auto adj = vertex_adjacency(Fv, n);
    const EdgeFaceCounts counts = edge_face_counts(Fv, adj);
    std::vector<char> boundary(static_cast<size_t>(n), 0);
    size_t e = 0;
    for (int a = 0; a < n; ++a)
      for (size_t k = 0; k < adj[a].size(); ++k) {
        const int faces = counts.faces[static_cast<size_t>(counts.start[a]) + k];
        if (adj[a][k] < a) {
          EXPECT_EQ(faces, 0);
          continue;
        }
        ASSERT_LT(e, edges.size());
        EXPECT_EQ(edges[e].i, a);
        EXPECT_EQ(edges[e].j, adj[a][k]);
        EXPECT_EQ(edges[e].faces, faces);
        if (faces == 1) boundary[a] = boundary[adj[a][k]] = 1;
        ++e;
      }
    EXPECT_EQ(e, edges.size());
    EXPECT_EQ(boundary_vertices(Fv, adj), boundary);
    std::map<std::pair<int, int>, int> directed;
    for (int f = 0; f < rows; ++f)
      for (int c = 0; c < 3; ++c) ++directed[{Fv(f, c), Fv(f, (c + 1) % 3)}];
    int flips = 0;
    for (const auto& [h, count] : directed) flips += count > 1;
    EXPECT_EQ(r.count(MeshDefect::InconsistentOrientation), flips);
  }
  const MeshReport all = validate_mesh(meshes.back().first, meshes.back().second);
  for (MeshDefect d : {MeshDefect::NonManifoldEdge, MeshDefect::NonManifoldVertex, MeshDefect::DuplicateFace,
                       MeshDefect::InconsistentOrientation, MeshDefect::DegenerateFace, MeshDefect::IndexOutOfRange})
    EXPECT_GT(all.count(d), 0) << mesh_defect_name(d) << "\n" << all.to_text();
}

// The 1→4 subdivision the big-input tests and benches use: #F × 4, #V + #E vertices, the same
// surface (old vertices unmoved, every new one the midpoint of its edge), clean, and every boundary
// loop twice as long.
TEST(MidpointSubdivide, FourTimesTheFacesSameSurfaceLoopsKept) {
  for (const char* file : {"edit/camelhead.ply", "edit/cylinder_coarse.ply"}) {
    const io::LoadResult lr = io::load_asset(test::data_path(file));
    ASSERT_TRUE(lr.status.ok()) << lr.status.message;
    const Mesh m = lr.asset.mesh();
    const Mesh s = midpoint_subdivide(m);
    const size_t edges = edge_uses(m.F).size();
    EXPECT_EQ(s.F.rows(), 4 * m.F.rows()) << file;
    EXPECT_EQ(static_cast<size_t>(s.V.rows()), m.V.rows() + edges) << file;
    EXPECT_EQ(s.V.topRows(m.V.rows()), m.V) << file;
    // Every new vertex is the midpoint of two old ones it sits between in a face.
    for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
      const int ab = s.F(4 * f, 1), a = m.F(f, 0), b = m.F(f, 1);
      EXPECT_LT((s.V.row(ab) - 0.5 * (m.V.row(a) + m.V.row(b))).norm(), 1e-15) << file;
    }
    const MeshReport r0 = validate_mesh(m.V, m.F), r1 = validate_mesh(s.V, s.F);
    EXPECT_TRUE(r1.defects.empty()) << file << "\n" << r1.to_text();
    ASSERT_EQ(r1.boundary_loops.size(), r0.boundary_loops.size()) << file;
    for (size_t k = 0; k < r0.boundary_loops.size(); ++k) EXPECT_EQ(r1.boundary_loops[k].size(), 2 * r0.boundary_loops[k].size());
    EXPECT_EQ(r1.num_components, r0.num_components);
  }
}

}  // namespace mm
