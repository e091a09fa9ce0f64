#include "mesh/topology.h"

#include <algorithm>
#include <cassert>
#include <functional>
#include <numeric>
#include <queue>

namespace mm {

std::vector<std::vector<int>> vertex_adjacency(const Eigen::MatrixXi& F, int n) {
  std::vector<std::vector<int>> adj(n);
  auto valid = [n](int a, int b) { return a != b && a >= 0 && b >= 0 && a < n && b < n; };
  {
    // Each list allocated once at its final size (growing them cost ~5 allocations per vertex).
    std::vector<int> count(static_cast<size_t>(std::max(n, 0)), 0);
    for (int f = 0; f < F.rows(); ++f)
      for (int c = 0; c < 3; ++c) {
        const int a = F(f, c), b = F(f, (c + 1) % 3);
        if (valid(a, b)) ++count[a], ++count[b];
      }
    for (int v = 0; v < n; ++v) adj[v].reserve(count[v]);
  }
  for (int f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      if (!valid(a, b)) continue;
      adj[a].push_back(b);
      adj[b].push_back(a);
    }
  }
  for (auto& list : adj) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return adj;
}

std::vector<int> k_ring(const std::vector<std::vector<int>>& adjacency, int seed, int k) {
  return k_ring(adjacency, std::vector<int>{seed}, k);
}

std::vector<int> k_ring(const std::vector<std::vector<int>>& adjacency,
                        const std::vector<int>& seeds, int k) {
  std::vector<char> seen(adjacency.size(), 0);
  std::vector<int> frontier, result;
  for (int s : seeds) {
    if (s < 0 || s >= static_cast<int>(adjacency.size()) || seen[s]) continue;
    seen[s] = 1;
    frontier.push_back(s);
    result.push_back(s);
  }
  for (int ring = 0; ring < k && !frontier.empty(); ++ring) {
    std::vector<int> next;
    for (int v : frontier)
      for (int w : adjacency[v])
        if (!seen[w]) {
          seen[w] = 1;
          next.push_back(w);
          result.push_back(w);
        }
    frontier.swap(next);
  }
  std::sort(result.begin(), result.end());
  return result;
}

Eigen::VectorXi vertex_components(const Eigen::MatrixXi& F, int n, int* count) {
  // Union-find with path halving; ids assigned in order of the smallest vertex.
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      if (a < 0 || b < 0 || a >= n || b >= n) continue;
      const int ra = find(a), rb = find(b);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  Eigen::VectorXi comp(n);
  std::vector<int> id_of_root(n, -1);
  int next = 0;
  for (int v = 0; v < n; ++v) {
    const int r = find(v);
    if (id_of_root[r] < 0) id_of_root[r] = next++;
    comp[v] = id_of_root[r];
  }
  if (count) *count = next;
  return comp;
}

std::vector<EdgeUse> edge_uses(const Eigen::MatrixXi& F) {
  std::vector<EdgeUse> out;
  if (F.rows() == 0) return out;
  const int n = F.maxCoeff() + 1;
  const int halves = static_cast<int>(F.rows()) * 3;
  auto ends = [&F](int h, int* lo, int* hi) {
    const int f = h / 3, c = h % 3;
    *lo = F(f, c);
    *hi = F(f, (c + 1) % 3);
    if (*lo > *hi) std::swap(*lo, *hi);
  };
  const VertexBuckets by_lo = bucket_by_vertex(n, halves, [&](int h) {
    int lo, hi;
    ends(h, &lo, &hi);
    return lo == hi ? -1 : lo;
  });
  out.reserve(static_cast<size_t>(halves) / 2 + 1);
  std::vector<int> his;
  for (int v = 0; v < n; ++v) {
    his.clear();
    for (int k = by_lo.start[v]; k < by_lo.start[v + 1]; ++k) {
      int lo, hi;
      ends(by_lo.items[k], &lo, &hi);
      his.push_back(hi);
    }
    std::sort(his.begin(), his.end());
    for (size_t k = 0; k < his.size();) {
      size_t e = k;
      while (e < his.size() && his[e] == his[k]) ++e;
      out.push_back({v, his[k], static_cast<int>(e - k)});
      k = e;
    }
  }
  return out;
}

EdgeFaceCounts edge_face_counts(const Eigen::MatrixXi& F, const std::vector<std::vector<int>>& adjacency) {
  const int n = static_cast<int>(adjacency.size());
  EdgeFaceCounts out;
  out.start.assign(static_cast<size_t>(n) + 1, 0);
  for (int v = 0; v < n; ++v) out.start[v + 1] = out.start[v] + static_cast<int>(adjacency[v].size());
  out.faces.assign(static_cast<size_t>(out.start[n]), 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      int a = F(f, c), b = F(f, (c + 1) % 3);
      if (a == b) continue;
      if (a > b) std::swap(a, b);
      if (a < 0 || b >= n) continue;  // vertex_adjacency drops these too
      const std::vector<int>& list = adjacency[a];
      const auto it = std::lower_bound(list.begin(), list.end(), b);
      assert(it != list.end() && *it == b && "edge_face_counts: adjacency is not the faces'");
      if (it == list.end() || *it != b) continue;
      ++out.faces[static_cast<size_t>(out.start[a] + (it - list.begin()))];
    }
  return out;
}

std::vector<char> boundary_vertices(const Eigen::MatrixXi& F, const std::vector<std::vector<int>>& adjacency) {
  const EdgeFaceCounts counts = edge_face_counts(F, adjacency);
  std::vector<char> boundary(adjacency.size(), 0);
  for (size_t a = 0; a < adjacency.size(); ++a)
    for (size_t k = 0; k < adjacency[a].size(); ++k)
      if (counts.faces[static_cast<size_t>(counts.start[a]) + k] == 1) boundary[a] = boundary[adjacency[a][k]] = 1;
  return boundary;
}

std::vector<VertexFans> non_manifold_vertices(const Eigen::MatrixXi& F, int n, const std::vector<char>* only) {
  const VertexBuckets vf_corners = bucket_by_vertex(n, static_cast<int>(F.rows()) * 3, [&](int h) {
    const int v = F(h / 3, h % 3);
    return only && !(*only)[v] ? -1 : v;
  });
  std::vector<int> faces;
  std::vector<VertexFans> out;
  std::vector<int> parent;
  // Per other vertex w: the vertex whose fans are being traced when w was last seen as a spoke,
  // and the first of its faces found on the spoke (v, w). Faces sharing a spoke share an edge at v.
  std::vector<int> spoke_of(static_cast<size_t>(std::max(n, 0)), -1), spoke_face(static_cast<size_t>(std::max(n, 0)), 0);
  for (int v = 0; v < n; ++v) {
    faces.clear();
    for (int k = vf_corners.start[v]; k < vf_corners.start[v + 1]; ++k) faces.push_back(vf_corners.items[k] / 3);
    if (faces.size() < 2) continue;
    parent.resize(faces.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&parent](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (size_t k = 0; k < faces.size(); ++k)
      for (int c = 0; c < 3; ++c) {
        const int w = F(faces[k], c);
        if (w == v) continue;
        if (spoke_of[w] != v) {
          spoke_of[w] = v;
          spoke_face[w] = static_cast<int>(k);
          continue;
        }
        const int ra = find(static_cast<int>(k)), rb = find(spoke_face[w]);
        if (ra != rb) parent[ra] = rb;
      }
    int fans = 0;
    for (size_t k = 0; k < faces.size(); ++k)
      if (find(static_cast<int>(k)) == static_cast<int>(k)) ++fans;
    if (fans > 1) out.push_back({v, fans});
  }
  return out;
}

std::vector<std::vector<int>> boundary_loops(const Eigen::MatrixXi& F, int n) {
  // Linear time, no ordered maps (1M-vertex grids): face edges (slots 3f + c) bucketed by their
  // smaller vertex, each bucket sorted by the larger one (buckets are a vertex's few edges), runs
  // counted; the directed half-edges a→b (face order) of edges used once are bucketed by a,
  // ascending, and chained with a cursor per vertex.
  const int nf = static_cast<int>(F.rows());
  auto valid = [n](int a, int b) { return a != b && a >= 0 && b >= 0 && a < n && b < n; };
  std::vector<int> start(static_cast<size_t>(n) + 1, 0);
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      if (valid(a, b)) ++start[std::min(a, b) + 1];
    }
  for (int v = 0; v < n; ++v) start[v + 1] += start[v];
  std::vector<std::pair<int, int>> bucket(start[n]);  // (larger vertex, slot)
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int c = 0; c < 3; ++c) {
        const int a = F(f, c), b = F(f, (c + 1) % 3);
        if (valid(a, b)) bucket[fill[std::min(a, b)]++] = {std::max(a, b), 3 * f + c};
      }
  }
  std::vector<char> single(3 * static_cast<size_t>(nf), 0);  // per slot: its edge has one face
  for (int v = 0; v < n; ++v) {
    const auto first = bucket.begin() + start[v], last = bucket.begin() + start[v + 1];
    std::sort(first, last);
    for (auto k = first; k != last;) {
      auto e = k;
      while (e != last && e->first == k->first) ++e;
      if (e - k == 1) single[k->second] = 1;
      k = e;
    }
  }
  std::vector<std::pair<int, int>> half_edges;
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c)
      if (single[3 * f + c]) half_edges.push_back({F(f, c), F(f, (c + 1) % 3)});
  return chain_boundary_loops(n, half_edges);
}

std::vector<std::vector<int>> chain_boundary_loops(int n, const std::vector<std::pair<int, int>>& half_edges) {
  std::vector<int> out_start(static_cast<size_t>(n) + 1, 0);
  for (const auto& h : half_edges) ++out_start[h.first + 1];
  for (int v = 0; v < n; ++v) out_start[v + 1] += out_start[v];
  std::vector<int> next(out_start[n]);  // outgoing boundary half-edges per vertex, ascending
  {
    std::vector<int> fill(out_start.begin(), out_start.end() - 1);
    for (const auto& h : half_edges) next[fill[h.first]++] = h.second;
  }
  std::vector<int> cursor(out_start.begin(), out_start.end() - 1);
  for (int v = 0; v < n; ++v) std::sort(next.begin() + out_start[v], next.begin() + out_start[v + 1]);
  auto remaining = [&](int v) { return cursor[v] < out_start[v + 1]; };
  std::vector<std::vector<int>> loops;
  for (int s = 0; s < n; ++s) {
    while (remaining(s)) {
      std::vector<int> loop{s};
      int v = s;
      while (remaining(v)) {
        const int w = next[cursor[v]++];  // the smallest unused successor
        if (w == s) break;
        loop.push_back(w);
        v = w;
      }
      loops.push_back(std::move(loop));
    }
  }
  return loops;
}

void relax_edge_distances(const Eigen::MatrixXd& V, const std::vector<std::vector<int>>& adjacency, int seed,
                          std::vector<double>* dist, double radius) {
  std::vector<double>& d = *dist;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  d[seed] = 0;
  queue.push({0.0, seed});
  while (!queue.empty()) {
    const auto [dv, v] = queue.top();
    queue.pop();
    if (dv > d[v]) continue;
    for (int w : adjacency[v]) {
      const double nd = dv + (V.row(v) - V.row(w)).norm();
      if (nd <= radius && nd < d[w]) {
        d[w] = nd;
        queue.push({nd, w});
      }
    }
  }
}

}  // namespace mm
