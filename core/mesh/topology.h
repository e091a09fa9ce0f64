// Topology queries on a triangle mesh (see mesh/mesh.h for conventions):
// vertex adjacency, k-ring neighbourhoods, connected components, boundary loops.
// All outputs are sorted / ordered deterministically (by vertex index), never in hash order.
#pragma once

#include <limits>
#include <utility>
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
// The loops of given boundary half-edges a→b (each vertex's outgoing ones taken in ascending
// order, loops started at the smallest vertex with one left): boundary_loops' second half, for
// callers that found the boundary edges themselves (validate_mesh). Vertices in [0, n).
std::vector<std::vector<int>> chain_boundary_loops(int n, const std::vector<std::pair<int, int>>& half_edges);

// Items 0..count-1 grouped by a vertex key in [0, n) by a counting sort (linear time): the items
// of vertex v are items[start[v]] .. items[start[v + 1] - 1], in increasing item order. key(i)
// returns the item's vertex, or -1 to leave it out.
struct VertexBuckets {
  std::vector<int> start;  // n + 1 offsets
  std::vector<int> items;
};
template <class Key>
VertexBuckets bucket_by_vertex(int n, int count, Key key) {
  VertexBuckets b;
  b.start.assign(static_cast<size_t>(n) + 1, 0);
  std::vector<int> k(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    k[i] = key(i);
    if (k[i] >= 0) ++b.start[k[i] + 1];
  }
  for (int v = 0; v < n; ++v) b.start[v + 1] += b.start[v];
  b.items.resize(b.start[n]);
  std::vector<int> fill(b.start.begin(), b.start.end() - 1);
  for (int i = 0; i < count; ++i)
    if (k[i] >= 0) b.items[fill[k[i]]++] = i;
  return b;
}

// Undirected edges (i < j) with the number of faces using each, sorted by (i, j). Linear time
// (faces bucketed by the edge's smaller vertex); indices must be >= 0.
struct EdgeUse {
  int i, j;    // endpoints, i < j
  int faces;   // number of faces containing this edge
};
std::vector<EdgeUse> edge_uses(const Eigen::MatrixXi& F);

// Faces per undirected edge, counted in the edge's smaller vertex's adjacency list: entry
// start[a] + k (start = prefix sums of the lists' sizes, n + 1 of them) counts the faces of F
// using edge (a, adjacency[a][k]) when a < adjacency[a][k] (0 for the other direction). The same
// counts as edge_uses without sorting or bucketing; `adjacency` must be vertex_adjacency of a
// superset of F's faces (sorted lists).
struct EdgeFaceCounts {
  std::vector<int> start, faces;
};
EdgeFaceCounts edge_face_counts(const Eigen::MatrixXi& F, const std::vector<std::vector<int>>& adjacency);

// Per vertex: 1 if it ends an edge used by exactly one face (the same flags as edge_uses'
// faces == 1), with `adjacency` = vertex_adjacency(F, n).
std::vector<char> boundary_vertices(const Eigen::MatrixXi& F, const std::vector<std::vector<int>>& adjacency);

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
