// HarmonicRetargeter's context-graph terms (paper 002 Sec. 6, Eq. 11–12): graph on the source,
// compatible nodes on the target by non-rigid ICP, E_spatial and E_volume as synthesis terms.
//
// Choices (the paper is silent or its formulation would refactor per frame):
// - Topology fixed at precompute (union of the pruned graphs of the calibration pose and of the
//   graph frames), node positions per frame: the normal matrix stays factored once.
// - T_spatial of Eq. 11 (Sorkine 2004's implicit per-node similarity) would put the source frame
//   into the matrix. Instead the target's Laplacian coordinates are asked to be
//     s·L·Pa(frame) + R_b(i)·(L·Va − s·L·Pa_rest)
//   (s = height ratio): the source's current Laplacian coordinates (the spatial relationship
//   between parts, contacts included), plus the target's own rest offset from the source's,
//   turned with the node's bone (R_b = polar factor of the source map's Jacobian at the bone's
//   midpoint). For identical characters this is exactly the source's Laplacian coordinates.
// - E_volume (Eq. 12): T_volume is the same per-bone rotation R_b of the rest Laplacian
//   coordinates of a volume graph on the target (below): the thickness vectors from the bones to
//   the surface keep their length and turn with their bone.
// - Volume graph (tetra-free): interior nodes = the used joints and `volume_bone_samples` points
//   per bone (kept when inside the target), chained along each bone; surface nodes = the first
//   `volume_surface_points` target collocation points (FPS order), each joined to its
//   `volume_neighbours` nearest interior nodes that it sees without crossing the surface.
// - Rows are divided by the mean edge length (ℓ, ℓ_v) so both terms are dimensionless like
//   E_affine, and the weights are means over rows (as the other terms).
#include <algorithm>
#include <cmath>
#include <string>

#include "mesh/mesh.h"
#include "retarget/harmonic_retarget.h"
#include "retarget/mfs_kernel.h"
#include "spatial/farthest_point_sampling.h"

namespace mm {

namespace retarget_detail {
Eigen::MatrixXd to_working(const Eigen::MatrixXd& V, const Eigen::RowVector3d& c, double L, const Eigen::Matrix3d& R);
}  // namespace retarget_detail

namespace context_terms_detail {

Eigen::MatrixXd graph_to_units(const Eigen::MatrixXd& X, const Eigen::RowVector3d& c, double L, const Eigen::Matrix3d& R) {
  Eigen::MatrixXd Y = (X * R) * L;
  Y.rowwise() += c;
  return Y;
}

// Nearest bone segment (index into bones) of a point; -1 when there are none.
int graph_nearest_bone(const Eigen::RowVector3d& x, const std::vector<std::pair<int, int>>& bones, const Eigen::MatrixXd& J) {
  int best = -1;
  double bd = 1e300;
  for (size_t b = 0; b < bones.size(); ++b) {
    const Eigen::RowVector3d a = J.row(bones[b].second), c = J.row(bones[b].first);
    const Eigen::RowVector3d d = c - a;
    const double t = d.squaredNorm() > 0 ? std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    const double dist = (x - (a + t * d)).squaredNorm();
    if (dist < bd) bd = dist, best = static_cast<int>(b);
  }
  return best;
}

// Rows of L with at least one neighbour, as a row-selected sparse matrix, and their indices.
Eigen::SparseMatrix<double> graph_nonempty_rows(const Eigen::SparseMatrix<double>& L, std::vector<int>* rows) {
  Eigen::SparseMatrix<double, Eigen::RowMajor> Lr(L);
  rows->clear();
  for (int i = 0; i < Lr.rows(); ++i)
    if (Lr.row(i).nonZeros() > 1) rows->push_back(i);
  Eigen::SparseMatrix<double> S(static_cast<Eigen::Index>(rows->size()), L.rows());
  std::vector<Eigen::Triplet<double>> t;
  for (size_t r = 0; r < rows->size(); ++r)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Lr, (*rows)[r]); it; ++it)
      t.emplace_back(static_cast<int>(r), static_cast<int>(it.col()), it.value());
  S.setFromTriplets(t.begin(), t.end());
  return S;
}

}  // namespace context_terms_detail

Eigen::MatrixXd HarmonicRetargeter::source_graph_nodes(const Eigen::MatrixXd& V_source) const {
  return src_nodes_.positions(V_source, src_F_);
}

Status HarmonicRetargeter::build_context_graph(const Eigen::MatrixXd& Xs, const Eigen::MatrixXi& Fs,
                                               const Eigen::MatrixXd& Xt, const Eigen::MatrixXi& Ft,
                                               const TriangleBvh& bvh_s, const TriangleBvh& bvh_t,
                                               const HarmonicRetargetOptions& opt) {
  using namespace context_terms_detail;
  const int up = std::clamp(opt.graph.up_axis, 0, 2);
  const double hs = Xs.col(up).maxCoeff() - Xs.col(up).minCoeff();
  const double ht = Xt.col(up).maxCoeff() - Xt.col(up).minCoeff();
  if (!(hs > 0 && ht > 0)) return Status::error(StatusCode::InvalidMesh, "context graph: a calibration shape has no height");
  graph_scale_ = ht / hs;
  src_F_ = Fs;

  // Nodes: the source singularities projected onto the source calibration surface (Sec. 6).
  src_nodes_ = project_to_surface(src_map_.singularities(), bvh_s, 1e-3);
  const int N = src_nodes_.size();
  if (N < 4) return Status::error(StatusCode::InvalidMesh, "context graph: fewer than 4 distinct nodes");
  // Body parts (Sec. 6.1 (1)): k-means of the source surface vertices seeded at the used joints.
  const BodyParts parts = body_parts(Xs, Js_rest_, opt.graph.kmeans_iterations);
  graph_.vertex_part = parts.label;
  graph_.part = nearest_centers(src_nodes_.P, parts.centers);
  // Pruned graph (Sec. 6.1 (2), (3)) at the calibration pose, then united with the graph frames'.
  graph_.calibration_edges = pruned_context_edges(src_nodes_.P, graph_.part, bvh_s, hs, opt.graph, &graph_.counts);
  graph_.edges = graph_.calibration_edges;
  for (const Eigen::MatrixXd& Vf : graph_frames_) {
    if (Vf.rows() != Xs.rows() || Vf.cols() != 3 || !Vf.allFinite())
      return Status::error(StatusCode::InvalidArgument, "context graph: a graph frame does not match the source surface");
    const Eigen::MatrixXd Xf = retarget_detail::to_working(Vf, cs_, Ls_, Eigen::Matrix3d::Identity());
    const TriangleBvh bvh_f(Xf, Fs);
    graph_.edges = edge_union(graph_.edges, pruned_context_edges(src_nodes_.positions(Xf, Fs), graph_.part, bvh_f, hs, opt.graph));
  }
  if (graph_.edges.empty()) return Status::error(StatusCode::InvalidMesh, "context graph: every edge was pruned");

  // Compatible nodes on the target (Sec. 6): non-rigid ICP of the source calibration surface
  // (the nodes plus FPS vertices, k-NN stiffness graph) onto the target, joints as landmarks.
  {
    const int extra = std::max(0, std::min<int>(opt.icp_points - N, static_cast<int>(Xs.rows())));
    const std::vector<int> fps = farthest_point_sampling(Xs, extra);
    Eigen::MatrixXd T(N + static_cast<Eigen::Index>(fps.size()), 3);
    T.topRows(N) = src_nodes_.P;
    for (size_t i = 0; i < fps.size(); ++i) T.row(N + i) = Xs.row(fps[i]);
    const int m = static_cast<int>(Js_rest_.rows());
    Eigen::VectorXi lv = nearest_centers(Js_rest_, T);
    // The template starts posed by the bones (source joints → target joints), the stiffness
    // graph is the rest template's: the ICP then only closes the shape difference.
    const bool posed = opt.icp_bone_start && !bones_.empty();
    const Eigen::MatrixXd Tp = posed ? articulated_points(T, Js_rest_, Jt_rest_, bones_) : T;
    const Eigen::MatrixXd Jp = posed ? articulated_points(Js_rest_, Js_rest_, Jt_rest_, bones_) : Js_rest_;
    NonrigidIcpResult icp = nonrigid_icp(Tp, knn_edges(T, opt.icp_neighbours), bvh_t, lv, Jp, Jt_rest_, opt.icp);
    if (!icp.status.ok()) return Status{icp.status.code, "context graph: " + icp.status.message};
    graph_.icp_converged = icp.converged;
    graph_.icp_residual = icp.mean_residual;
    Va_.resize(N, 3);
    if (icp.converged) {
      Va_ = icp.closest.topRows(N);
      warnings_.push_back("context graph: target nodes by non-rigid ICP (mean residual " +
                          std::to_string(icp.mean_residual).substr(0, 6) + " of the diagonal, " +
                          std::to_string(icp.solves) + " solves)");
    } else {
      // Fallback: the affine map that best takes the source joints to the target joints (least
      // squares, 4 by 3), then the closest target point.
      Eigen::MatrixXd A(m, 4);
      A << Js_rest_, Eigen::VectorXd::Ones(m);
      const Eigen::MatrixXd M = A.colPivHouseholderQr().solve(Jt_rest_);
      Eigen::MatrixXd B(N, 4);
      B << src_nodes_.P, Eigen::VectorXd::Ones(N);
      const Eigen::MatrixXd Y = B * M;
      for (int i = 0; i < N; ++i) Va_.row(i) = bvh_t.closest_point(Y.row(i).transpose()).point.transpose();
      warnings_.push_back("context graph: non-rigid ICP did not converge (mean residual " +
                          std::to_string(icp.mean_residual).substr(0, 6) + ", valid " +
                          std::to_string(icp.valid_fraction).substr(0, 5) +
                          "); target nodes by the joints' affine fit and closest points instead");
    }
  }
  graph_.target_face.resize(N);
  graph_.target_barycentric.resize(N, 3);
  for (int i = 0; i < N; ++i) {
    const ClosestPoint cp = bvh_t.closest_point(Va_.row(i).transpose());
    graph_.target_face[i] = cp.face;
    graph_.target_barycentric.row(i) = cp.barycentric.transpose();
  }
  const Eigen::MatrixXd& U = tgt_map_.singularities();
  KtVa_ = mfs_kernel(Va_, U);

  // E_spatial (Eq. 11).
  std::vector<int> rows;
  Lsp_ = graph_nonempty_rows(uniform_graph_laplacian(N, graph_.edges), &rows);
  {
    double len = 0;
    for (const auto& [i, j] : graph_.edges) len += (src_nodes_.P.row(i) - src_nodes_.P.row(j)).norm();
    graph_sp_len_ = std::max(1e-9, len / graph_.edges.size());
  }
  sp_corr_ = Lsp_ * Va_ - graph_scale_ * (Lsp_ * src_nodes_.P);
  sp_bone_.resize(static_cast<Eigen::Index>(rows.size()));
  for (size_t r = 0; r < rows.size(); ++r) sp_bone_[r] = graph_nearest_bone(Va_.row(rows[r]), bones_, Jt_rest_);
  term_spatial_ = synth_.add_term({"spatial", Eigen::MatrixXd(Lsp_ * KtVa_) / graph_sp_len_,
                                   opt.w_spatial / std::max<size_t>(1, rows.size()), false});

  // E_volume (Eq. 12) on the tetra-free volume graph of the target calibration shape.
  {
    const SurfaceSamples& C = tgt_map_.collocation();
    const int ns = std::min(opt.volume_surface_points, C.size());
    std::vector<Eigen::RowVector3d> inner;
    std::vector<int> inner_bone;
    std::vector<std::pair<int, int>> edges;  // over [surface | interior]
    const int nb = static_cast<int>(bones_.size());
    // Interior: each bone's samples from child to parent, joints shared between bones.
    std::vector<int> joint_node(Jt_rest_.rows(), -1);
    auto joint_index = [&](int j, int b) {
      if (joint_node[j] < 0) {
        joint_node[j] = static_cast<int>(inner.size());
        inner.push_back(Jt_rest_.row(j));
        inner_bone.push_back(b);
      }
      return joint_node[j];
    };
    for (int b = 0; b < nb; ++b) {
      const auto [c, p] = bones_[b];
      int prev = ns + joint_index(c, b);
      for (int k = 1; k <= opt.volume_bone_samples; ++k) {
        const double a = double(k) / (opt.volume_bone_samples + 1);
        const Eigen::RowVector3d x = (1 - a) * Jt_rest_.row(c) + a * Jt_rest_.row(p);
        if (!bvh_t.inside(x.transpose())) continue;
        inner.push_back(x);
        inner_bone.push_back(b);
        const int cur = ns + static_cast<int>(inner.size()) - 1;
        edges.push_back({std::min(prev, cur), std::max(prev, cur)});
        prev = cur;
      }
      const int last = ns + joint_index(p, b);
      edges.push_back({std::min(prev, last), std::max(prev, last)});
    }
    for (int j = 0; j < Jt_rest_.rows(); ++j) joint_index(j, nb > 0 ? 0 : -1);
    const int ni = static_cast<int>(inner.size());
    Eigen::MatrixXd Xv(ns + ni, 3);
    Xv.topRows(ns) = C.P.topRows(ns);
    for (int i = 0; i < ni; ++i) Xv.row(ns + i) = inner[i];
    std::vector<int> bone_of(ns + ni, -1);
    for (int i = 0; i < ni; ++i) bone_of[ns + i] = inner_bone[i];
    const double margin = 1e-4;
    for (int i = 0; i < ns; ++i) {
      std::vector<std::pair<double, int>> d;
      for (int k = 0; k < ni; ++k) d.push_back({(Xv.row(i) - Xv.row(ns + k)).squaredNorm(), k});
      std::sort(d.begin(), d.end());
      int linked = 0;
      for (size_t q = 0; q < d.size() && q < 8 && linked < opt.volume_neighbours; ++q) {
        const Eigen::Vector3d a = Xv.row(i).transpose(), b = Xv.row(ns + d[q].second).transpose();
        const Eigen::Vector3d dir = (b - a).normalized();
        if (bvh_t.segment_hits(a + margin * dir, b)) continue;
        if (linked == 0) bone_of[i] = inner_bone[d[q].second];
        edges.push_back({i, ns + d[q].second});
        ++linked;
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<int> vrows;
    const Eigen::SparseMatrix<double> Lv = graph_nonempty_rows(uniform_graph_laplacian(ns + ni, edges), &vrows);
    double len = 0;
    for (const auto& [i, j] : edges) len += (Xv.row(i) - Xv.row(j)).norm();
    graph_vol_len_ = std::max(1e-9, len / std::max<size_t>(1, edges.size()));
    vol_delta_ = Lv * Xv;
    vol_bone_.resize(static_cast<Eigen::Index>(vrows.size()));
    for (size_t r = 0; r < vrows.size(); ++r) vol_bone_[r] = bone_of[vrows[r]];
    term_volume_ = synth_.add_term({"volume", Eigen::MatrixXd(Lv * mfs_kernel(Xv, U)) / graph_vol_len_,
                                    (opt.articulated_base && !bones_.empty() ? opt.w_volume_base : opt.w_volume) /
                                        std::max<size_t>(1, vrows.size()),
                                    false});
    graph_.volume_nodes = graph_to_units(Xv, ct_, Lt_, R_);
    graph_.volume_edges = edges;
    graph_.volume_surface = ns;
  }
  // Source Jacobians at the bone midpoints (for R_b per frame); multiplied by V S⁻¹ after factoring.
  {
    Eigen::MatrixXd mids(bones_.size(), 3);
    for (size_t b = 0; b < bones_.size(); ++b)
      mids.row(b) = 0.5 * (Js_rest_.row(bones_[b].first) + Js_rest_.row(bones_[b].second));
    DmidVS_ = mfs_gradient(mids, src_map_.singularities());
  }
  graph_.source_nodes = graph_to_units(src_nodes_.P, cs_, Ls_, Eigen::Matrix3d::Identity());
  graph_.target_nodes = graph_to_units(Va_, ct_, Lt_, R_);
  graph_on_ = true;
  return Status::success();
}

}  // namespace mm
