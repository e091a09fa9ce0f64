#include "edit/selection.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "mesh/topology.h"

namespace mm {

namespace {

std::string edit_sel_vertex_error(const char* what, int index, int n) {
  return std::string(what) + " vertex index " + std::to_string(index) + " is out of range (mesh has " +
         std::to_string(n) + " vertices)";
}

// The vertices within geodesic (edge-path) distance `radius` of `seed` (mesh/topology.h).
void edit_sel_geodesic_disk(const Eigen::MatrixXd& V, const std::vector<std::vector<int>>& adjacency,
                            int seed, double radius, std::vector<char>* mark) {
  std::vector<double> dist(adjacency.size(), std::numeric_limits<double>::infinity());
  relax_edge_distances(V, adjacency, seed, &dist, radius);
  for (size_t v = 0; v < dist.size(); ++v)
    if (std::isfinite(dist[v])) (*mark)[v] = 1;
}

}  // namespace

SelectionResult select_vertices(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                const VertexSelection& sel) {
  SelectionResult out;
  const int n = static_cast<int>(V.rows());
  std::vector<char> mark(n, 0);
  for (int i : sel.indices) {
    if (i < 0 || i >= n) {
      out.status = Status::error(StatusCode::InvalidArgument, edit_sel_vertex_error("selected", i, n));
      return out;
    }
    mark[i] = 1;
  }
  for (const auto& s : sel.spheres) {
    if (!s.center.allFinite() || !std::isfinite(s.radius) || s.radius < 0) {
      out.status = Status::error(StatusCode::InvalidArgument,
                                 "sphere selector needs a finite center and a radius ≥ 0");
      return out;
    }
    const double r2 = s.radius * s.radius;
    for (int v = 0; v < n; ++v)
      if ((V.row(v).transpose() - s.center).squaredNorm() <= r2) mark[v] = 1;
  }
  for (const auto& b : sel.boxes) {
    if (!b.min.allFinite() || !b.max.allFinite() || (b.min.array() > b.max.array()).any()) {
      out.status = Status::error(StatusCode::InvalidArgument,
                                 "box selector needs finite corners with min ≤ max on every axis");
      return out;
    }
    for (int v = 0; v < n; ++v) {
      const Eigen::Vector3d p = V.row(v).transpose();
      if ((p.array() >= b.min.array()).all() && (p.array() <= b.max.array()).all()) mark[v] = 1;
    }
  }
  if (!sel.slabs.empty() && n > 0) {
    const Eigen::RowVector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
    for (const auto& s : sel.slabs) {
      if (s.axis < -1 || s.axis > 2 || !std::isfinite(s.from) || !std::isfinite(s.to) || s.from > s.to) {
        out.status = Status::error(StatusCode::InvalidArgument,
                                   "slab selector needs axis -1 (longest), 0, 1 or 2 and from ≤ to");
        return out;
      }
      int axis = s.axis;
      if (axis < 0) (hi - lo).maxCoeff(&axis);
      const double extent = hi[axis] - lo[axis];
      for (int v = 0; v < n; ++v) {
        const double t = extent > 0 ? (V(v, axis) - lo[axis]) / extent : 0.0;
        if (t >= s.from && t <= s.to) mark[v] = 1;
      }
    }
  }
  if (!sel.rings.empty() || !sel.disks.empty()) {
    const auto adjacency = vertex_adjacency(F, n);
    for (const auto& r : sel.rings) {
      if (r.vertex < 0 || r.vertex >= n) {
        out.status = Status::error(StatusCode::InvalidArgument, edit_sel_vertex_error("k-ring seed", r.vertex, n));
        return out;
      }
      if (r.k < 0) {
        out.status = Status::error(StatusCode::InvalidArgument, "k-ring selector needs k ≥ 0");
        return out;
      }
      for (int v : k_ring(adjacency, r.vertex, r.k)) mark[v] = 1;
    }
    for (const auto& d : sel.disks) {
      if (d.vertex < 0 || d.vertex >= n) {
        out.status = Status::error(StatusCode::InvalidArgument, edit_sel_vertex_error("geodesic disk seed", d.vertex, n));
        return out;
      }
      if (!std::isfinite(d.radius) || d.radius < 0) {
        out.status = Status::error(StatusCode::InvalidArgument, "geodesic disk selector needs a radius ≥ 0");
        return out;
      }
      edit_sel_geodesic_disk(V, adjacency, d.vertex, d.radius, &mark);
    }
  }
  for (int v = 0; v < n; ++v)
    if (mark[v]) out.vertices.push_back(v);
  return out;
}

std::vector<int> components_containing(const Eigen::MatrixXi& F, int num_vertices,
                                       const std::vector<int>& seeds) {
  int count = 0;
  const Eigen::VectorXi comp = vertex_components(F, num_vertices, &count);
  std::vector<char> wanted(count, 0);
  for (int s : seeds)
    if (s >= 0 && s < num_vertices) wanted[comp[s]] = 1;
  std::vector<int> out;
  for (int v = 0; v < num_vertices; ++v)
    if (wanted[comp[v]]) out.push_back(v);
  return out;
}

}  // namespace mm
