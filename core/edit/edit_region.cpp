#include "edit/laplacian_editor_impl.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "edit/selection.h"
#include "mesh/topology.h"
#include "operators/operators.h"

namespace mm {

namespace edit_detail {

// Non-manifold checks restricted to the faces around the unknowns (exact there: every face of an
// edge or vertex of an unknown is in `faces`).
Status edit_check_region_manifold(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<int>& faces,
                                  const std::vector<char>& is_unknown, const std::vector<std::vector<int>>& adjacency) {
  for (int f : faces) {
    const Eigen::Vector3d p0 = V.row(F(f, 0)).transpose(), p1 = V.row(F(f, 1)).transpose(),
                          p2 = V.row(F(f, 2)).transpose();
    const double area2 = (p1 - p0).cross(p2 - p0).norm();
    const double scale = std::max({(p1 - p0).squaredNorm(), (p2 - p0).squaredNorm(), (p2 - p1).squaredNorm()});
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2) || !(area2 > 1e-12 * scale))
      return Status::error(StatusCode::InvalidMesh,
                           "the edited region has a degenerate (zero-area) face " + std::to_string(f) + " (vertices " +
                               std::to_string(F(f, 0)) + ", " + std::to_string(F(f, 1)) + ", " +
                               std::to_string(F(f, 2)) + "); cotangent weights are undefined there");
  }
  // Non-manifold edges and vertices over the region's faces (mesh/topology.h). Counts within
  // the subset never exceed the true counts, so > 2 faces at an edge is always a real defect;
  // the fans of an unknown vertex are exact (all its faces are in the subset).
  Eigen::MatrixXi Fs(faces.size(), 3);
  for (size_t k = 0; k < faces.size(); ++k) Fs.row(static_cast<Eigen::Index>(k)) = F.row(faces[k]);
  int bad = 0, first_a = -1, first_b = -1;
  const EdgeFaceCounts uses = edge_face_counts(Fs, adjacency);
  for (size_t a = 0; a < adjacency.size(); ++a)
    for (size_t k = 0; k < adjacency[a].size(); ++k)
      if (uses.faces[static_cast<size_t>(uses.start[a]) + k] > 2 && bad++ == 0)
        first_a = static_cast<int>(a), first_b = adjacency[a][k];
  if (bad > 0)
    return Status::error(StatusCode::InvalidMesh, "the edited region has " + std::to_string(bad) +
                                                      " non-manifold edges, first at vertices " + std::to_string(first_a) +
                                                      "-" + std::to_string(first_b));
  const std::vector<VertexFans> nm = non_manifold_vertices(Fs, static_cast<int>(V.rows()), &is_unknown);
  if (!nm.empty())
    return Status::error(StatusCode::InvalidMesh, "the edited region has " + std::to_string(nm.size()) +
                                                      " non-manifold vertices (several face fans), first at vertex " +
                                                      std::to_string(nm[0].vertex));
  return Status::success();
}

}  // namespace edit_detail

using namespace edit_detail;

Status LaplacianEditor::Impl::build_region(const Eigen::MatrixXd& Vin, const Eigen::MatrixXi& F,
                                           const EditRegion& region, EditBuild* s) {
  // Only the defects no method can work with are checked here (cheaply, O(#V + #F)); the
  // manifold checks below are restricted to the edited region.
  if (Vin.rows() == 0 || F.rows() == 0 || Vin.cols() != 3)
    return Status::error(StatusCode::InvalidMesh, "mesh is empty (no vertices or no faces)");
  for (int v = 0; v < Vin.rows(); ++v)
    if (!Vin.row(v).allFinite())
      return Status::error(StatusCode::InvalidMesh, "vertex " + std::to_string(v) + " has a non-finite coordinate");
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (F(f, c) < 0 || F(f, c) >= Vin.rows())
        return Status::error(StatusCode::InvalidMesh, "face " + std::to_string(f) + " has vertex index " +
                                                          std::to_string(F(f, c)) + ", out of range (mesh has " +
                                                          std::to_string(Vin.rows()) + " vertices)");
  V = Vin;
  const int n = static_cast<int>(V.rows());
  num_handles = static_cast<int>(region.handles.size());
  if (num_handles == 0)
    return Status::error(StatusCode::InvalidArgument, "no handle given: an edit needs at least one handle vertex set");
  std::vector<int> gid(n, -2);  // -2 free, -1 fixed, h handle
  for (int h = 0; h < num_handles; ++h) {
    if (region.handles[h].empty())
      return Status::error(StatusCode::InvalidArgument, "handle " + std::to_string(h) + " is empty");
    for (int v : region.handles[h]) {
      if (v < 0 || v >= n)
        return Status::error(StatusCode::InvalidArgument, "handle " + std::to_string(h) + " vertex index " +
                                                              std::to_string(v) + " is out of range (mesh has " +
                                                              std::to_string(n) + " vertices)");
      if (gid[v] >= 0 && gid[v] != h)
        return Status::error(StatusCode::InvalidArgument, "vertex " + std::to_string(v) + " is in handles " +
                                                              std::to_string(gid[v]) + " and " + std::to_string(h) +
                                                              "; handles must not overlap");
      gid[v] = h;
    }
  }
  for (int v : region.fixed) {
    if (v < 0 || v >= n)
      return Status::error(StatusCode::InvalidArgument, "fixed vertex index " + std::to_string(v) +
                                                            " is out of range (mesh has " + std::to_string(n) + " vertices)");
    if (gid[v] >= 0)
      return Status::error(StatusCode::InvalidArgument, "vertex " + std::to_string(v) + " is both fixed and in handle " +
                                                            std::to_string(gid[v]));
    gid[v] = -1;
  }
  std::vector<int> roi = region.roi;
  for (int v : roi)
    if (v < 0 || v >= n)
      return Status::error(StatusCode::InvalidArgument, "ROI vertex index " + std::to_string(v) +
                                                            " is out of range (mesh has " + std::to_string(n) + " vertices)");
  if (roi.empty()) {
    std::vector<int> seeds;
    for (const auto& h : region.handles) seeds.insert(seeds.end(), h.begin(), h.end());
    roi = components_containing(F, n, seeds);
  }
  std::vector<char> in_roi(n, 0);
  for (int v : roi) in_roi[v] = 1;

  const bool soft_mode = opt.soft_constraint_weight > 0;
  std::vector<char> unknown(n, 0);
  for (int v = 0; v < n; ++v) unknown[v] = in_roi[v] && (soft_mode || gid[v] == -2);
  std::vector<int> U;
  for (int v = 0; v < n; ++v)
    if (unknown[v]) U.push_back(v);
  if (U.empty())
    return Status::error(StatusCode::InvalidArgument,
                         "the region of interest has no free vertex (every ROI vertex is a handle or fixed)");

  auto adj = vertex_adjacency(F, n);
  // Faces around the unknowns: complete 1-rings for their Laplacian rows.
  std::vector<int> faces;
  for (int f = 0; f < F.rows(); ++f)
    if (unknown[F(f, 0)] || unknown[F(f, 1)] || unknown[F(f, 2)]) faces.push_back(f);
  if (Status s = edit_check_region_manifold(V, F, faces, unknown, adj); !s.ok()) return s;
  for (int v : U)
    if (adj[v].empty())
      return Status::error(StatusCode::InvalidMesh, "vertex " + std::to_string(v) + " of the region of interest is isolated");

  // Every free component needs a constraint, or it floats (singular system).
  {
    std::vector<int> comp(n, -1);
    for (int s : U) {
      if (comp[s] >= 0) continue;
      std::vector<int> stack = {s};
      comp[s] = s;
      bool anchored = false;
      while (!stack.empty()) {
        const int v = stack.back();
        stack.pop_back();
        if (soft_mode && gid[v] != -2) anchored = true;
        for (int w : adj[v]) {
          if (!unknown[w]) {
            anchored = true;
            continue;
          }
          if (comp[w] < 0) {
            comp[w] = s;
            stack.push_back(w);
          }
        }
      }
      if (!anchored)
        return Status::error(StatusCode::InvalidArgument,
                             "free vertices around vertex " + std::to_string(s) +
                                 " are not connected to any handle or fixed vertex; add a constraint there or shrink the ROI");
    }
  }
  s->n = n;
  s->adj = std::move(adj);
  s->gid = std::move(gid);
  s->in_roi = std::move(in_roi);
  s->unknown = std::move(unknown);
  s->U = std::move(U);
  s->faces = std::move(faces);
  s->soft_mode = soft_mode;
  return Status::success();
}

void LaplacianEditor::Impl::region_edge_scale(const Eigen::MatrixXi& F, EditBuild* s) {
  const std::vector<int>& faces = s->faces;
  // ---- the scale h: mean edge length around the unknowns
  double h = 0;
  long edge_count = 0;
  for (int f : faces)
    for (int c = 0; c < 3; ++c) {
      h += (V.row(F(f, c)) - V.row(F(f, (c + 1) % 3))).norm();
      ++edge_count;
    }
  h /= static_cast<double>(std::max<long>(edge_count, 1));
  stats.mean_edge_length = h;

  s->h = h;
}

void LaplacianEditor::Impl::number_locally(const Eigen::MatrixXi& F, EditBuild* s) {
  const int n = s->n;
  const std::vector<int>& faces = s->faces;
  const std::vector<int>& gid = s->gid;
  const std::vector<int>& U = s->U;
  const std::vector<char>& unknown = s->unknown;
  const std::vector<char>& in_roi = s->in_roi;
  const auto& adj = s->adj;
  const bool implicit = s->implicit;
  const int r = s->r;
  const double h = s->h;
  std::vector<int>& pair_centers = s->pair_centers;
  std::vector<int>& active_centers = s->active_centers;
  std::vector<char>& is_active = s->is_active;
  // ---- local numbering
  std::vector<int> g2l(n, -1);
  std::vector<int> K;  // known vertices referenced (global)
  std::vector<char> referenced(n, 0);
  for (int f : faces)
    for (int c = 0; c < 3; ++c) referenced[F(f, c)] = 1;
  for (int v = 0; v < n; ++v)
    if (gid[v] >= 0) referenced[v] = 1;  // every handle vertex moves, even those no system row touches
  std::vector<int> center_index(n, -1);
  if (implicit) {
    for (size_t c = 0; c < grads.centers.size(); ++c) center_index[grads.centers[c]] = static_cast<int>(c);
    // Active centers: gradient involves an unknown.
    is_active.assign(grads.centers.size(), 0);
    for (size_t c = 0; c < grads.centers.size(); ++c)
      for (int e = grads.offsets[c]; e < grads.offsets[c + 1]; ++e)
        if (unknown[grads.stencil[e]]) {
          is_active[c] = 1;
          break;
        }
    for (size_t c = 0; c < grads.centers.size(); ++c)
      if (is_active[c]) active_centers.push_back(grads.centers[c]);
    pair_centers = k_ring(adj, active_centers, r);
    for (int v : pair_centers) {
      const int c = center_index[v];
      assert(c >= 0 && "pair center without a stencil");
      for (int e = grads.offsets[c]; e < grads.offsets[c + 1]; ++e) referenced[grads.stencil[e]] = 1;
    }
  }
  l2g = U;
  nU = static_cast<int>(U.size());
  for (int v = 0; v < n; ++v)
    if (referenced[v] && !unknown[v]) K.push_back(v);
  l2g.insert(l2g.end(), K.begin(), K.end());
  nL = static_cast<int>(l2g.size());
  for (int l = 0; l < nL; ++l) g2l[l2g[l]] = l;
  group.resize(nL);
  for (int l = 0; l < nL; ++l) {
    const int v = l2g[l];
    group[l] = (gid[v] == -2 && !in_roi[v]) ? -1 : gid[v];  // outside the ROI: fixed
  }
  soft.assign(nU, 0.0);
  const double ws = opt.soft_constraint_weight / (h * h);
  for (int l = 0; l < nU; ++l)
    if (group[l] != -2) soft[l] = ws;
  // Laplacian rows (E_L, Eq. 5, and Eq. 9/10) belong to unconstrained vertices only, as in the paper;
  // soft-constrained unknowns get their soft row instead, so that soft → hard as the weight grows.
  has_row.assign(nU, 1);
  for (int l = 0; l < nU; ++l)
    if (group[l] != -2) has_row[l] = 0;
  stats.free_vertices = nU;
  stats.known_vertices = nL - nU;
  if (implicit) {
    stats.degenerate_vertices = static_cast<int>(grads.degenerate.size());
    stats.displaced_vertices = static_cast<int>(grads.displaced.size());
    stats.widened_stencils = static_cast<int>(grads.widened.size());
    stats.max_condition = grads.max_condition;
    stencil_local.resize(grads.stencil.size());
    for (size_t e = 0; e < grads.stencil.size(); ++e) stencil_local[e] = g2l[grads.stencil[e]];
    center_of.assign(nU, -1);
    for (int l = 0; l < nU; ++l) center_of[l] = center_index[l2g[l]];
    std::vector<char> disp(n, 0);
    for (int v : grads.displaced) disp[v] = 1;
    for (int l = 0; l < nU; ++l)
      if (disp[l2g[l]]) displaced_unknowns.push_back(l);
  }

  s->g2l = std::move(g2l);
  s->center_index = std::move(center_index);
}

// D_i = −(2/A_i)·W_i (cotangent, paper 001 Sec. 2) or D_i = −L_i/deg_i (uniform) on the region's
// faces: rows of the unknowns in local numbering (nU by nL) and the factor turning W_i into D_i.
void LaplacianEditor::Impl::laplacian_rows(const EditBuild& s, const Eigen::MatrixXd& P, EditSparse* Wout,
                                           Eigen::VectorXd* dscale) const {
  const bool cot = s.cot;
  const Eigen::MatrixXi& Fsub = s.Fsub;
  const int n = s.n;
  const std::vector<int>& g2l = s.g2l;
  const auto& adj = s.adj;
  // Rows of the unknowns (as columns of the symmetric matrix) in local numbering, plus the
  // factor turning W_i into the paper's D_i.
  const EditSparse W = cot ? cotan_stiffness(P, Fsub) : uniform_laplacian(Fsub, n);
  Eigen::VectorXd area;
  if (cot) area = mass_diagonal(P, Fsub, MassType::Voronoi);
  dscale->resize(nU);
  for (int l = 0; l < nU; ++l) {
    const int v = l2g[l];
    (*dscale)[l] = cot ? -2.0 / area[v] : -1.0 / static_cast<double>(adj[v].size());
  }
  // Row l holds W's column v = l2g[l] in local numbering; W is symmetric bit for bit (each
  // off-diagonal pair sums the same terms in the same order), so column k of the result is
  // column l2g[k] of W restricted to the unknowns, already in ascending order (U is sorted,
  // and the unknowns come first in the local numbering).
  Wout->resize(nU, nL);
  Eigen::Index total = 0;
  for (int k = 0; k < nL; ++k)
    for (EditSparse::InnerIterator it(W, l2g[k]); it; ++it) total += static_cast<unsigned>(g2l[it.row()]) < static_cast<unsigned>(nU) ? 1 : 0;
  Wout->resizeNonZeros(total);
  int* outer = Wout->outerIndexPtr();
  int* rows = Wout->innerIndexPtr();
  double* vals = Wout->valuePtr();
  int at = 0;
  for (int k = 0; k < nL; ++k) {
    outer[k] = at;
    for (EditSparse::InnerIterator it(W, l2g[k]); it; ++it) {
      const int l = g2l[it.row()];
      if (static_cast<unsigned>(l) >= static_cast<unsigned>(nU)) continue;
      rows[at] = l;
      vals[at++] = it.value();
    }
  }
  outer[nL] = at;
}

}  // namespace mm
