#include "merge/cut.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "mesh/mesh.h"
#include "mesh/topology.h"

namespace mm {

namespace {

CutResult cut_error(StatusCode code, const std::string& message) {
  CutResult r;
  r.status = Status::error(code, message);
  return r;
}

double mean_edge_length(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  double sum = 0;
  long count = 0;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      sum += (V.row(F(f, k)) - V.row(F(f, (k + 1) % 3))).norm();
      ++count;
    }
  return count ? sum / static_cast<double>(count) : 0.0;
}

// Keeps the faces of the connected piece (through shared vertices) that contains face `seed`.
Eigen::MatrixXi piece_of(const Eigen::MatrixXi& F, int n, int seed) {
  int count = 0;
  const Eigen::VectorXi comp = vertex_components(F, n, &count);
  const int c = comp[F(seed, 0)];
  std::vector<int> keep;
  for (int f = 0; f < F.rows(); ++f)
    if (comp[F(f, 0)] == c) keep.push_back(f);
  Eigen::MatrixXi out(static_cast<Eigen::Index>(keep.size()), 3);
  for (size_t k = 0; k < keep.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = F.row(keep[k]);
  return out;
}

CutResult finish_cut(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, std::vector<int> from) {
  CutResult r;
  r.from = std::move(from);
  compact_mesh(V, F, &r.V, &r.F, &r.from);
  r.boundary_loops = static_cast<int>(boundary_loops(r.F, static_cast<int>(r.V.rows())).size());
  return r;
}

}  // namespace

void compact_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, Eigen::MatrixXd* Vout,
                  Eigen::MatrixXi* Fout, std::vector<int>* from) {
  const int n = static_cast<int>(V.rows());
  std::vector<int> remap(n, -1);
  int m = 0;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (remap[F(f, k)] < 0) remap[F(f, k)] = 0;
  for (int v = 0; v < n; ++v)
    if (remap[v] == 0) remap[v] = m++;
  Eigen::MatrixXd Vn(m, 3);
  std::vector<int> origin(m);
  const bool compose = from && static_cast<int>(from->size()) == n;
  for (int v = 0; v < n; ++v)
    if (remap[v] >= 0) {
      Vn.row(remap[v]) = V.row(v);
      origin[remap[v]] = compose ? (*from)[v] : v;
    }
  Eigen::MatrixXi Fn(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) Fn(f, k) = remap[F(f, k)];
  *Vout = std::move(Vn);
  *Fout = std::move(Fn);
  if (from) *from = std::move(origin);
}

CutResult cut_plane(const Eigen::MatrixXd& Vin, const Eigen::MatrixXi& F, const Eigen::Vector3d& p,
                    const Eigen::Vector3d& nin, const Eigen::Vector3d& keep, const PlaneCutOptions& opt) {
  if (Vin.rows() == 0 || F.rows() == 0) return cut_error(StatusCode::InvalidMesh, "cut: the mesh is empty");
  if (!p.allFinite() || !nin.allFinite() || !keep.allFinite() || !(nin.norm() > 0))
    return cut_error(StatusCode::InvalidArgument, "cut: the plane needs a finite point and a non-zero normal");
  if (!(opt.snap_fraction >= 0 && opt.snap_fraction < 0.5))
    return cut_error(StatusCode::InvalidArgument, "cut: snap_fraction must be in [0, 0.5)");
  Eigen::Vector3d n = nin.normalized();
  const double side = n.dot(keep - p);
  if (side == 0) return cut_error(StatusCode::InvalidArgument, "cut: the point to keep lies on the cut plane");
  if (side < 0) n = -n;  // the kept side is where d > 0
  Eigen::MatrixXd V = Vin;
  const int nv = static_cast<int>(V.rows());
  const double snap = opt.snap_fraction * mean_edge_length(V, F);
  std::vector<double> d(nv);
  for (int v = 0; v < nv; ++v) {
    d[v] = n.dot(V.row(v).transpose() - p);
    if (std::abs(d[v]) <= snap) {  // onto the plane: no slivers along the cut
      V.row(v) -= d[v] * n.transpose();
      d[v] = 0;
    }
  }
  std::vector<Eigen::RowVector3d> extra;
  std::vector<int> from(nv);
  for (int v = 0; v < nv; ++v) from[v] = v;
  std::map<std::pair<int, int>, int> edge_point;  // crossing edge (i < j) → new vertex
  auto crossing = [&](int i, int j) {
    const auto key = std::minmax(i, j);
    auto it = edge_point.find(key);
    if (it != edge_point.end()) return it->second;
    const int a = key.first, b = key.second;
    const double t = d[a] / (d[a] - d[b]);
    extra.push_back(V.row(a) + t * (V.row(b) - V.row(a)));
    const int id = nv + static_cast<int>(extra.size()) - 1;
    edge_point.emplace(key, id);
    return id;
  };
  std::vector<Eigen::Vector3i> out;
  out.reserve(F.rows());
  auto position = [&](int v) -> Eigen::RowVector3d { return v < nv ? Eigen::RowVector3d(V.row(v)) : extra[v - nv]; };
  for (int f = 0; f < F.rows(); ++f) {
    const int c[3] = {F(f, 0), F(f, 1), F(f, 2)};
    if (d[c[0]] >= 0 && d[c[1]] >= 0 && d[c[2]] >= 0) {
      if (d[c[0]] > 0 || d[c[1]] > 0 || d[c[2]] > 0) out.emplace_back(c[0], c[1], c[2]);
      continue;
    }
    if (d[c[0]] <= 0 && d[c[1]] <= 0 && d[c[2]] <= 0) continue;
    // Clip the triangle to d ≥ 0 (Sutherland–Hodgman on one plane), keeping the corner order.
    int poly[4], m = 0;
    for (int k = 0; k < 3; ++k) {
      const int a = c[k], b = c[(k + 1) % 3];
      if (d[a] >= 0) poly[m++] = a;
      if ((d[a] > 0 && d[b] < 0) || (d[a] < 0 && d[b] > 0)) poly[m++] = crossing(a, b);
    }
    if (m == 3) {
      out.emplace_back(poly[0], poly[1], poly[2]);
    } else if (m == 4) {  // quad: split along the shorter diagonal
      if ((position(poly[0]) - position(poly[2])).norm() <= (position(poly[1]) - position(poly[3])).norm()) {
        out.emplace_back(poly[0], poly[1], poly[2]);
        out.emplace_back(poly[0], poly[2], poly[3]);
      } else {
        out.emplace_back(poly[0], poly[1], poly[3]);
        out.emplace_back(poly[1], poly[2], poly[3]);
      }
    }
  }
  if (out.empty()) return cut_error(StatusCode::InvalidMesh, "cut: nothing of the mesh lies on the kept side of the plane");
  Eigen::MatrixXd Vall(nv + static_cast<int>(extra.size()), 3);
  Vall.topRows(nv) = V;
  for (size_t k = 0; k < extra.size(); ++k) Vall.row(nv + static_cast<Eigen::Index>(k)) = extra[k];
  from.resize(Vall.rows(), -1);
  Eigen::MatrixXi Fc(static_cast<Eigen::Index>(out.size()), 3);
  for (size_t k = 0; k < out.size(); ++k) Fc.row(static_cast<Eigen::Index>(k)) = out[k].transpose();
  // The piece nearest to the keep point (by its closest face centroid).
  int best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (int f = 0; f < Fc.rows(); ++f) {
    const Eigen::RowVector3d cen = (Vall.row(Fc(f, 0)) + Vall.row(Fc(f, 1)) + Vall.row(Fc(f, 2))) / 3.0;
    const double dist = (cen - keep.transpose()).squaredNorm();
    if (dist < best_d) {
      best_d = dist;
      best = f;
    }
  }
  return finish_cut(Vall, piece_of(Fc, static_cast<int>(Vall.rows()), best), std::move(from));
}

CutResult cut_disk(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int center, double radius) {
  const int nv = static_cast<int>(V.rows());
  if (nv == 0 || F.rows() == 0) return cut_error(StatusCode::InvalidMesh, "cut: the mesh is empty");
  if (center < 0 || center >= nv)
    return cut_error(StatusCode::InvalidArgument, "cut: disk center vertex " + std::to_string(center) +
                                                      " is out of range (the mesh has " + std::to_string(nv) +
                                                      " vertices)");
  if (!(radius > 0) || !std::isfinite(radius))
    return cut_error(StatusCode::InvalidArgument, "cut: the disk radius must be a positive number");
  const auto adj = vertex_adjacency(F, nv);
  std::vector<double> dist(nv, std::numeric_limits<double>::infinity());
  relax_edge_distances(V, adj, center, &dist, radius);
  std::vector<char> removed(F.rows(), 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (dist[F(f, k)] < radius) removed[f] = 1;
  // Grow the hole until no vertex has two fans (the hole touching itself).
  for (int round = 0; round < 64; ++round) {
    std::vector<int> keep;
    for (int f = 0; f < F.rows(); ++f)
      if (!removed[f]) keep.push_back(f);
    if (keep.empty()) break;
    Eigen::MatrixXi Fk(static_cast<Eigen::Index>(keep.size()), 3);
    for (size_t k = 0; k < keep.size(); ++k) Fk.row(static_cast<Eigen::Index>(k)) = F.row(keep[k]);
    const auto bad = non_manifold_vertices(Fk, nv);
    if (bad.empty()) break;
    std::vector<char> is_bad(nv, 0);
    for (const VertexFans& b : bad) is_bad[b.vertex] = 1;
    for (int f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        if (is_bad[F(f, k)]) removed[f] = 1;
  }
  std::vector<int> keep;
  for (int f = 0; f < F.rows(); ++f)
    if (!removed[f]) keep.push_back(f);
  if (keep.empty()) return cut_error(StatusCode::InvalidMesh, "cut: the disk covers the whole mesh; use a smaller radius");
  Eigen::MatrixXi Fk(static_cast<Eigen::Index>(keep.size()), 3);
  for (size_t k = 0; k < keep.size(); ++k) Fk.row(static_cast<Eigen::Index>(k)) = F.row(keep[k]);
  // Largest remaining piece.
  int count = 0;
  const Eigen::VectorXi comp = vertex_components(Fk, nv, &count);
  std::vector<int> faces_of(count, 0);
  for (int f = 0; f < Fk.rows(); ++f) ++faces_of[comp[Fk(f, 0)]];
  const int big = static_cast<int>(std::max_element(faces_of.begin(), faces_of.end()) - faces_of.begin());
  int seed = 0;
  for (int f = 0; f < Fk.rows(); ++f)
    if (comp[Fk(f, 0)] == big) {
      seed = f;
      break;
    }
  std::vector<int> from(nv);
  for (int v = 0; v < nv; ++v) from[v] = v;
  return finish_cut(V, piece_of(Fk, nv, seed), std::move(from));
}

}  // namespace mm
