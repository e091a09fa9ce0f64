// Topology queries on a triangle mesh (see mesh/mesh.h for conventions):
// vertex adjacency, k-ring neighbourhoods, connected components, boundary loops.
// All outputs are sorted / ordered deterministically (by vertex index), never in hash order.
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

namespace mm {

// For each vertex, its neighbours (vertices sharing an edge), sorted ascending, no duplicates.
// F: #F by 3; n: number of vertices (isolated vertices get an empty list).
std::vector<std::vector<int>> vertex_adjacency(const Eigen::MatrixXi& F, int n);

// Vertices within k edges of `seed` (k = 0 gives {seed}), sorted ascending.
std::vector<int> k_ring(const std::vector<std::vector<int>>& adjacency, int seed, int k);

// Dijkstra over edge lengths |V_v − V_w| from `seed`, lowering *dist (#V, +inf where unknown) where
// a shorter path is found and not relaxing past `radius`. Called once per seed with the same
// *dist it gives the minimum over seeds (farthest-point sampling); with a fresh *dist the vertices
// within `radius` are those with a finite entry (geodesic disks). Deterministic: ties are broken
// by vertex index.
void relax_edge_distances(const Eigen::MatrixXd& V, const std::vector<std::vector<int>>& adjacency, int seed,
                          std::vector<double>* dist, double radius = std::numeric_limits<double>::infinity());

// Vertices within k edges of any of `seeds`, sorted ascending.
std::vector<int> k_ring(const std::vector<std::vector<int>>& adjacency,
                        const std::vector<int>& seeds, int k);

// Connected components through shared edges. Returns the component id of every vertex
// (0-based, numbered in order of their smallest vertex; isolated vertices get their own id)
// and sets *count to the number of components.
Eigen::VectorXi vertex_components(const Eigen::MatrixXi& F, int n, int* count);

// Boundary loops: edges used by exactly one face, chained into closed loops of vertex
// indices following the face orientation. Loops are ordered by their smallest vertex, and
// each loop starts at its smallest vertex. Boundary edges that do not close into a loop
// (non-manifold boundaries) end their chain where it cannot be continued.
std::vector<std::vector<int>> boundary_loops(const Eigen::MatrixXi& F, int n);

// Undirected edges (i < j) with the number of faces using each, sorted by (i, j).
struct EdgeUse {
  int i, j;    // endpoints, i < j
  int faces;   // number of faces containing this edge
};
std::vector<EdgeUse> edge_uses(const Eigen::MatrixXi& F);

// Non-manifold vertices: the faces around a vertex must form one fan (faces connected through
// edges incident to the vertex). Returns (vertex, number of fans) for every vertex with more
// than one fan, ascending. F: faces without repeated indices; `only` (size n) restricts the
// check to the marked vertices. Non-manifold edges are the edge_uses with faces > 2.
struct VertexFans {
  int vertex;
  int fans;
};
std::vector<VertexFans> non_manifold_vertices(const Eigen::MatrixXi& F, int n,
                                              const std::vector<char>* only = nullptr);

}  // namespace mm
