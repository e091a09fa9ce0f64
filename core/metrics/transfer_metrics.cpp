#include "metrics/transfer_metrics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <map>
#include <iterator>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "linalg/rigid_fit.h"
#include "mesh/mesh.h"
#include "mesh/topology.h"

namespace mm {

namespace transfer_metrics_detail {

Eigen::VectorXd umbrella_magnitude(const Eigen::MatrixXd& V, const std::vector<std::vector<int>>& adj) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(V.rows());
  for (int i = 0; i < V.rows(); ++i) {
    if (adj[i].empty()) continue;
    Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
    for (int k : adj[i]) mean += V.row(k);
    m[i] = (V.row(i) - mean / adj[i].size()).norm();
  }
  return m;
}

// Per face: dot of its unit normal with the area-weighted mean normal of its edge neighbours.
Eigen::VectorXd neighbour_agreement(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                    const std::vector<std::vector<int>>& face_neighbours) {
  Eigen::MatrixXd N(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    N.row(f) = (b - a).cross(c - a).transpose();  // area-weighted
  }
  Eigen::VectorXd out(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    Eigen::RowVector3d m = Eigen::RowVector3d::Zero();
    for (int g : face_neighbours[f]) m += N.row(g);
    const double l = N.row(f).norm() * m.norm();
    out[f] = l > 0 ? N.row(f).dot(m) / l : 1.0;
  }
  return out;
}

}  // namespace transfer_metrics_detail

TransferMetrics transfer_metrics(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXi& F) {
  using namespace transfer_metrics_detail;
  TransferMetrics out;
  if (A.rows() != B.rows() || A.cols() != 3 || B.cols() != 3) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "meshes differ in size (" + std::to_string(A.rows()) + " and " + std::to_string(B.rows()) +
                                   " vertices): per-vertex comparison needs the same vertex order");
    return out;
  }
  const int n = static_cast<int>(A.rows());
  const double D = bounding_box_diagonal(B);
  if (n > 0 && D > 0) {
    const Eigen::VectorXd e = (A - B).rowwise().norm() / D;
    out.vertex_error_mean = e.mean();
    out.vertex_error_max = e.maxCoeff();
  }
  const auto adj = vertex_adjacency(F, n);
  const Eigen::VectorXd la = umbrella_magnitude(A, adj), lb = umbrella_magnitude(B, adj);
  if (lb.sum() > 0) out.laplacian_change = (la - lb).cwiseAbs().sum() / lb.sum();
  // Undirected edges (ordered set: deterministic sum).
  std::set<std::pair<int, int>> edges;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  double sum = 0;
  int count = 0;
  for (const auto& e : edges) {
    const double lb_e = (B.row(e.first) - B.row(e.second)).norm();
    if (lb_e > 0) {
      const double d = std::abs((A.row(e.first) - A.row(e.second)).norm() / lb_e - 1.0);
      sum += d;
      ++count;
      out.edge_distortion_max = std::max(out.edge_distortion_max, d);
    }
  }
  out.edge_distortion_mean = count ? sum / count : 0.0;
  const std::vector<int> flipped = flipped_faces(A, B, F, face_neighbours(F)), collapsed = collapsed_faces(A, B, F);
  out.flipped_faces = static_cast<int>(flipped.size());
  std::vector<int> only_collapsed;
  std::set_difference(collapsed.begin(), collapsed.end(), flipped.begin(), flipped.end(), std::back_inserter(only_collapsed));
  out.collapsed_faces = static_cast<int>(only_collapsed.size());
  return out;
}

std::vector<std::vector<int>> face_neighbours(const Eigen::MatrixXi& F) {
  std::map<std::pair<int, int>, std::vector<int>> edge_faces;  // ordered: deterministic
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      edge_faces[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  std::vector<std::vector<int>> fn(F.rows());
  for (const auto& [e, faces] : edge_faces)
    for (int f : faces)
      for (int g : faces)
        if (f != g) fn[f].push_back(g);
  return fn;
}

std::vector<int> flipped_faces(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXi& F,
                               const std::vector<std::vector<int>>& neighbours) {
  using namespace transfer_metrics_detail;
  const Eigen::VectorXd agree_a = neighbour_agreement(A, F, neighbours), agree_b = neighbour_agreement(B, F, neighbours);
  std::vector<int> out;
  for (int f = 0; f < F.rows(); ++f)
    if (agree_a[f] < 0 && agree_b[f] > 0.5) out.push_back(f);
  return out;
}

std::vector<int> collapsed_faces(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXi& F) {
  auto areas = [&F](const Eigen::MatrixXd& V) {
    Eigen::VectorXd a(F.rows());
    for (int f = 0; f < F.rows(); ++f) {
      const Eigen::Vector3d p = V.row(F(f, 0)), q = V.row(F(f, 1)), r = V.row(F(f, 2));
      a[f] = 0.5 * (q - p).cross(r - p).norm();
    }
    return a;
  };
  std::vector<int> out;
  if (F.rows() == 0) return out;
  const Eigen::VectorXd a = areas(A), b = areas(B);
  const double sa = a.sum(), sb = b.sum();
  if (!(sa > 0) || !(sb > 0)) return out;
  // a_f / sa < 1e-3 · b_f / sb, without dividing by a rest area that may be 0.
  const double k = 1e-3 * sa / sb;
  for (int f = 0; f < F.rows(); ++f)
    if (a[f] < k * b[f]) out.push_back(f);
  return out;
}

double aligned_vertex_error(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  assert(A.rows() == B.rows() && A.cols() == 3 && B.cols() == 3 && "aligned_vertex_error: A and B differ in shape");
  if (A.rows() == 0) return 0;
  RigidFitOptions o;
  o.scale = true;
  const RigidFit fit = fit_rigid(A, B, o);
  const Eigen::MatrixXd aligned = ((fit.s * A * fit.R.transpose()).rowwise() + fit.t.transpose());
  const double D = bounding_box_diagonal(B);
  return (aligned - B).rowwise().norm().mean() / (D > 0 ? D : 1.0);
}

}  // namespace mm
