#include "spectral/landmarks.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>

#include "mesh/topology.h"

namespace mm {

Status check_landmarks(const std::vector<LandmarkPair>& pairs, int reference_vertices, int source_vertices,
                       int min_landmarks) {
  if (static_cast<int>(pairs.size()) < min_landmarks)
    return Status::error(StatusCode::InvalidArgument,
                         "only " + std::to_string(pairs.size()) + " landmark pairs given; the coupled bases need at least " +
                             std::to_string(min_landmarks) + " (about 30 well-spread pairs work best)");
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto& p = pairs[i];
    if (p.reference < 0 || p.reference >= reference_vertices)
      return Status::error(StatusCode::InvalidArgument,
                           "landmark pair " + std::to_string(i) + ": reference vertex " + std::to_string(p.reference) +
                               " is out of range (the reference has " + std::to_string(reference_vertices) + " vertices)");
    if (p.source < 0 || p.source >= source_vertices)
      return Status::error(StatusCode::InvalidArgument,
                           "landmark pair " + std::to_string(i) + ": source vertex " + std::to_string(p.source) +
                               " is out of range (the source has " + std::to_string(source_vertices) + " vertices)");
    for (size_t j = 0; j < i; ++j)
      if (pairs[j].reference == p.reference && pairs[j].source == p.source)
        return Status::error(StatusCode::InvalidArgument,
                             "landmark pairs " + std::to_string(j) + " and " + std::to_string(i) + " are the same");
  }
  return Status::success();
}

LandmarkFunctions landmark_functions(const Eigen::MatrixXi& F_reference, const Eigen::VectorXd& mass_reference,
                                     const Eigen::MatrixXi& F_source, const Eigen::VectorXd& mass_source,
                                     const std::vector<LandmarkPair>& pairs, const LandmarkOptions& opt) {
  LandmarkFunctions out;
  const int nr = static_cast<int>(mass_reference.size()), ns = static_cast<int>(mass_source.size());
  out.status = check_landmarks(pairs, nr, ns, opt.min_landmarks);
  if (!out.status.ok()) return out;
  const auto adj_r = vertex_adjacency(F_reference, nr);
  const auto adj_s = vertex_adjacency(F_source, ns);
  const double total_r = mass_reference.sum(), total_s = mass_source.sum();
  const int p = static_cast<int>(pairs.size());
  out.reference.setZero(nr, p);
  out.source.setZero(ns, p);
  out.source_rings.resize(p);
  auto area = [](const std::vector<int>& region, const Eigen::VectorXd& mass) {
    double a = 0;
    for (int v : region) a += mass[v];
    return a;
  };
  for (int j = 0; j < p; ++j) {
    const std::vector<int> region_r = k_ring(adj_r, pairs[j].reference, opt.reference_rings);
    const double ar = area(region_r, mass_reference);
    const double target = ar / total_r;
    // Source rings: the k whose normalized area is closest (first k on ties).
    int best_k = 1;
    double best_err = std::numeric_limits<double>::infinity();
    std::vector<int> best_region;
    for (int k = 1; k <= opt.max_source_rings; ++k) {
      std::vector<int> region = k_ring(adj_s, pairs[j].source, k);
      const double err = std::abs(area(region, mass_source) / total_s - target);
      if (err < best_err) {
        best_err = err;
        best_k = k;
        best_region = std::move(region);
      }
    }
    out.source_rings[j] = best_k;
    const double as = area(best_region, mass_source);
    if (!(ar > 0) || !(as > 0)) {
      out.status = Status::error(StatusCode::InvalidMesh,
                                 "landmark pair " + std::to_string(j) + " lies in a region of zero area");
      return out;
    }
    for (int v : region_r) out.reference(v, j) = 1.0 / ar;
    for (int v : best_region) out.source(v, j) = 1.0 / as;
  }
  return out;
}

std::vector<int> farthest_point_landmarks(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int count) {
  const int n = static_cast<int>(V.rows());
  std::vector<int> out;
  if (n == 0 || count <= 0) return out;
  const auto adj = vertex_adjacency(F, n);
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  // Edge-length Dijkstra from each new sample into the running minimum (mesh/topology.h).
  auto relax_from = [&](int seed, std::vector<double>& d) { relax_edge_distances(V, adj, seed, &d); };
  auto farthest = [&](const std::vector<double>& d) {
    int best = 0;
    for (int i = 1; i < n; ++i)
      if (std::isfinite(d[i]) && (!std::isfinite(d[best]) || d[i] > d[best])) best = i;
    return best;
  };
  std::vector<double> from0(n, std::numeric_limits<double>::infinity());
  relax_from(0, from0);
  int next = farthest(from0);
  while (static_cast<int>(out.size()) < std::min(count, n)) {
    out.push_back(next);
    relax_from(next, dist);
    next = farthest(dist);
    if (dist[next] == 0) break;  // every reachable vertex is a landmark already
  }
  return out;
}

}  // namespace mm
