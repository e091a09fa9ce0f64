#include "merge/seam_zip.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "merge/transition.h"
#include "mesh/topology.h"
#include "operators/operators.h"

namespace mm {

namespace {

constexpr double kPi = 3.14159265358979323846;

double min_corner_angle_deg(const Eigen::MatrixXd& V, int a, int b, int c) {
  const int idx[3] = {a, b, c};
  double best = 180;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d u = (V.row(idx[(k + 1) % 3]) - V.row(idx[k])).transpose();
    const Eigen::Vector3d w = (V.row(idx[(k + 2) % 3]) - V.row(idx[k])).transpose();
    const double nu = u.norm(), nw = w.norm();
    if (!(nu > 0 && nw > 0)) return 0;
    best = std::min(best, std::acos(std::clamp(u.dot(w) / (nu * nw), -1.0, 1.0)) * 180 / kPi);
  }
  return best;
}

Eigen::Vector3d face_normal(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int f) {
  const Eigen::Vector3d a = V.row(F(f, 0)).transpose(), b = V.row(F(f, 1)).transpose(), c = V.row(F(f, 2)).transpose();
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double len = n.norm();
  return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

using EdgeFaces = std::map<std::pair<int, int>, std::vector<int>>;

EdgeFaces faces_by_edge(const Eigen::MatrixXi& F, const std::vector<int>& faces) {
  EdgeFaces ef;
  for (int f : faces)
    for (int k = 0; k < 3; ++k) ef[std::minmax(F(f, k), F(f, (k + 1) % 3))].push_back(f);
  return ef;
}

}  // namespace

void seam_dihedral_angles(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<int>& faces,
                          double* max_deg, double* mean_deg) {
  // Faces sharing an edge with `faces`, found through the whole mesh.
  std::vector<char> wanted_vertex(V.rows(), 0);
  for (int f : faces)
    for (int k = 0; k < 3; ++k) wanted_vertex[F(f, k)] = 1;
  std::vector<int> near;
  for (int f = 0; f < F.rows(); ++f)
    if (wanted_vertex[F(f, 0)] || wanted_vertex[F(f, 1)] || wanted_vertex[F(f, 2)]) near.push_back(f);
  const EdgeFaces ef = faces_by_edge(F, near);
  std::vector<char> is_seam(F.rows(), 0);
  for (int f : faces) is_seam[f] = 1;
  double mx = 0, sum = 0;
  long count = 0;
  for (const auto& [edge, fs] : ef) {
    if (fs.size() != 2 || !(is_seam[fs[0]] || is_seam[fs[1]])) continue;
    const double c = std::clamp(face_normal(V, F, fs[0]).dot(face_normal(V, F, fs[1])), -1.0, 1.0);
    const double deg = std::acos(c) * 180 / kPi;
    mx = std::max(mx, deg);
    sum += deg;
    ++count;
  }
  *max_deg = mx;
  *mean_deg = count ? sum / static_cast<double>(count) : 0.0;
}

ZipResult zip_meshes(const Eigen::MatrixXd& Vt, const Eigen::MatrixXi& Ft, const Eigen::MatrixXd& Vs,
                     const Eigen::MatrixXi& Fs, const std::vector<SeamCurves>& seams, const ZipOptions& opt) {
  ZipResult r;
  const int nt = static_cast<int>(Vt.rows()), ns = static_cast<int>(Vs.rows());
  const int S = static_cast<int>(seams.size());
  // ---- band of target faces touching each target loop
  std::vector<int> seam_of(nt, -1);
  if (opt.enabled)
    for (int i = 0; i < S; ++i)
      for (int v : seams[i].target_loop) seam_of[v] = i;
  std::vector<int> removed_by(Ft.rows(), -1);
  std::vector<int> kept;
  r.seams.assign(opt.enabled ? S : 0, MergeSeamReport{});
  for (int f = 0; f < Ft.rows(); ++f) {
    for (int k = 0; k < 3 && removed_by[f] < 0; ++k) removed_by[f] = seam_of[Ft(f, k)];
    if (removed_by[f] < 0) kept.push_back(f);
    else ++r.seams[removed_by[f]].removed_faces;
  }
  Eigen::MatrixXi Fr(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t k = 0; k < kept.size(); ++k) Fr.row(static_cast<Eigen::Index>(k)) = Ft.row(kept[k]);
  // ---- the new target boundary next to each seam (the inner side of the band)
  std::vector<std::vector<int>> inner(S);
  if (opt.enabled) {
    std::vector<int> band_of(nt, -1);  // band vertex (not on a loop) → seam
    for (int f = 0; f < Ft.rows(); ++f)
      if (removed_by[f] >= 0)
        for (int k = 0; k < 3; ++k)
          if (seam_of[Ft(f, k)] < 0) {
            const int v = Ft(f, k);
            if (band_of[v] >= 0 && band_of[v] != removed_by[f])
              r.status = Status::error(StatusCode::InvalidMesh,
                                       "target loops " + std::to_string(band_of[v]) + " and " +
                                           std::to_string(removed_by[f]) +
                                           " are one triangle apart: their zip bands overlap");
            band_of[v] = removed_by[f];
          }
    if (!r.status.ok()) return r;
    std::vector<char> referenced(nt, 0);
    for (int f = 0; f < Fr.rows(); ++f)
      for (int k = 0; k < 3; ++k) referenced[Fr(f, k)] = 1;
    const auto loops = boundary_loops(Fr, nt);
    for (int i = 0; i < S; ++i) {
      int found = -1, count = 0;
      for (int l = 0; l < static_cast<int>(loops.size()); ++l) {
        bool all = true;
        for (int v : loops[l]) all = all && band_of[v] == i;
        if (all) {
          found = l;
          ++count;
        }
      }
      int expected = 0;
      for (int v = 0; v < nt; ++v) expected += band_of[v] == i && referenced[v];
      if (count != 1 || static_cast<int>(loops[found].size()) != expected) {
        r.status = Status::error(StatusCode::InvalidMesh,
                                 "the band of target triangles along target loop " + std::to_string(i) +
                                     " cannot be removed cleanly (the target is too coarse or too thin there: "
                                     "removing it does not leave one boundary loop); refine the target near "
                                     "its boundary or cut it elsewhere");
        return r;
      }
      inner[i] = loops[found];
    }
    std::vector<char> only(nt, 0);
    for (int v = 0; v < nt; ++v) only[v] = band_of[v] >= 0;
    if (!non_manifold_vertices(Fr, nt, &only).empty()) {
      r.status = Status::error(StatusCode::InvalidMesh,
                               "removing the band along a target loop leaves a vertex touched twice by the new "
                               "boundary; refine the target near its boundary");
      return r;
    }
  }
  // ---- merged vertex array: remaining target vertices, then the source
  r.target_map.assign(nt, -1);
  int m = 0;
  {
    std::vector<char> used(nt, 0);
    for (int f = 0; f < Fr.rows(); ++f)
      for (int k = 0; k < 3; ++k) used[Fr(f, k)] = 1;
    for (int v = 0; v < nt; ++v)
      if (used[v]) r.target_map[v] = m++;
  }
  r.source_offset = m;
  r.V.resize(m + ns, 3);
  for (int v = 0; v < nt; ++v)
    if (r.target_map[v] >= 0) r.V.row(r.target_map[v]) = Vt.row(v);
  r.V.bottomRows(ns) = Vs;
  std::vector<Eigen::Vector3i> faces;
  faces.reserve(Fr.rows() + Fs.rows() + 4 * S);
  for (int f = 0; f < Fr.rows(); ++f)
    faces.emplace_back(r.target_map[Fr(f, 0)], r.target_map[Fr(f, 1)], r.target_map[Fr(f, 2)]);
  for (int f = 0; f < Fs.rows(); ++f) faces.emplace_back(m + Fs(f, 0), m + Fs(f, 1), m + Fs(f, 2));
  // ---- triangulate each gap: I runs along the target loop (same orientation), J along the
  // source loop. Advancing on I adds (I[i+1], I[i], J[j]); on J adds (J[j], J[j+1], I[i]), which
  // keeps the target's orientation (docs/merge.md). Both curves advance in step by normalized arc length.
  std::vector<std::vector<int>> zip_faces(S);
  std::vector<TransitionSeam> transition(S);
  for (int i = 0; opt.enabled && i < S; ++i) {
    std::vector<int> I(inner[i].size()), J(seams[i].source_loop.size());
    for (size_t k = 0; k < I.size(); ++k) I[k] = r.target_map[inner[i][k]];
    for (size_t k = 0; k < J.size(); ++k) J[k] = m + seams[i].source_loop[k];
    const int mi = static_cast<int>(I.size()), mj = static_cast<int>(J.size());
    int i0 = 0;
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < mi; ++k) {
      const double d = (r.V.row(I[k]) - r.V.row(J[0])).squaredNorm();
      if (d < best) {
        best = d;
        i0 = k;
      }
    }
    // Normalized arc length along each curve from the aligned start pair.
    auto arc = [&](const std::vector<int>& C, int start) {
      const int n = static_cast<int>(C.size());
      std::vector<double> u(n + 1, 0.0);
      for (int k = 0; k < n; ++k)
        u[k + 1] = u[k] + (r.V.row(C[(start + k + 1) % n]) - r.V.row(C[(start + k) % n])).norm();
      for (double& x : u) x = u[n] > 0 ? x / u[n] : 0.0;
      return u;
    };
    const std::vector<double> ui = arc(I, i0), uj = arc(J, 0);
    for (int k = 0; k < mi; ++k) transition[i].target_side.push_back(I[(i0 + k) % mi]);
    transition[i].source_side = J;
    int ci = 0, cj = 0;
    while (ci < mi || cj < mj) {
      const int a = I[(i0 + ci) % mi], a1 = I[(i0 + ci + 1) % mi];
      const int b = J[cj % mj], b1 = J[(cj + 1) % mj];
      // Advance the curve whose next vertex comes first along the seam; between near-ties take
      // the shorter new diagonal.
      bool advance_i;
      if (ci == mi) advance_i = false;
      else if (cj == mj) advance_i = true;
      else if (std::abs(ui[ci + 1] - uj[cj + 1]) < 0.25 / std::max(mi, mj))
        advance_i = (r.V.row(a1) - r.V.row(b)).squaredNorm() <= (r.V.row(a) - r.V.row(b1)).squaredNorm();
      else advance_i = ui[ci + 1] < uj[cj + 1];
      zip_faces[i].push_back(static_cast<int>(faces.size()));
      if (advance_i) {
        faces.emplace_back(a1, a, b);
        ++ci;
      } else {
        faces.emplace_back(b, b1, a);
        ++cj;
      }
    }
  }
  r.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) r.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  if (!opt.enabled) return r;
  // ---- transition regions (Sec. 5.3): details of both sides blended across the seam
  const bool blend = opt.transition_target_width > 0 && opt.transition_source_width > 0;
  if (blend) {
    // Mean-curvature normals of the surfaces the vertices came from (transition.h).
    Eigen::MatrixXd H(r.V.rows(), 3);
    const Eigen::MatrixXd Ht = (cotan_stiffness(Vt, Ft) * Vt).array().colwise() / mass_diagonal(Vt, Ft).array().max(1e-300);
    for (int v = 0; v < nt; ++v)
      if (r.target_map[v] >= 0) H.row(r.target_map[v]) = Ht.row(v);
    Eigen::MatrixXd Hs = (cotan_stiffness(Vs, Fs) * Vs).array().colwise() / mass_diagonal(Vs, Fs).array().max(1e-300);
    // The source's merged loops are boundaries there: take the mean of their interior neighbours.
    std::vector<char> loop_vertex(ns, 0);
    for (const SeamCurves& c : seams)
      for (int v : c.source_loop) loop_vertex[v] = 1;
    const auto sadj = vertex_adjacency(Fs, ns);
    for (int v = 0; v < ns; ++v) {
      if (!loop_vertex[v]) continue;
      Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
      int count = 0;
      for (int w : sadj[v])
        if (!loop_vertex[w]) {
          sum += Hs.row(w);
          ++count;
        }
      Hs.row(v) = count ? Eigen::RowVector3d(sum / count) : Eigen::RowVector3d::Zero();
    }
    H.bottomRows(ns) = Hs;
    TransitionReport tr;
    r.status = blend_transition(&r.V, r.F, m, transition, opt.transition_target_width, opt.transition_source_width, H,
                                &tr);
    if (!r.status.ok()) return r;
    r.transition_vertices = tr.region_vertices;
  }
  // ---- umbrella smoothing [Tau95] of the vertices near the seams
  std::vector<int> seeds;
  for (const auto& zf : zip_faces)
    for (int f : zf)
      for (int k = 0; k < 3; ++k) seeds.push_back(r.F(f, k));
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  const auto adj = vertex_adjacency(r.F, static_cast<int>(r.V.rows()));
  const std::vector<int> region = k_ring(adj, seeds, opt.smoothing_rings);
  for (int it = 0; it < opt.smoothing_iterations; ++it) {
    Eigen::MatrixXd next(region.size(), 3);
    for (size_t k = 0; k < region.size(); ++k) {
      const int v = region[k];
      Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
      for (int w : adj[v]) mean += r.V.row(w);
      mean /= static_cast<double>(std::max<size_t>(adj[v].size(), 1));
      next.row(static_cast<Eigen::Index>(k)) = r.V.row(v) + opt.smoothing_step * (mean - r.V.row(v));
    }
    for (size_t k = 0; k < region.size(); ++k) r.V.row(region[k]) = next.row(static_cast<Eigen::Index>(k));
  }
  // ---- reports
  for (int i = 0; i < S; ++i) {
    MergeSeamReport& rep = r.seams[i];
    rep.zip_faces = static_cast<int>(zip_faces[i].size());
    rep.min_angle_deg = 180;
    std::vector<char> seam_vertex(r.V.rows(), 0);
    for (int f : zip_faces[i]) {
      rep.min_angle_deg = std::min(rep.min_angle_deg, min_corner_angle_deg(r.V, r.F(f, 0), r.F(f, 1), r.F(f, 2)));
      for (int k = 0; k < 3; ++k) seam_vertex[r.F(f, k)] = 1;
    }
    std::vector<int> near;
    for (int f = 0; f < r.F.rows(); ++f)
      if (seam_vertex[r.F(f, 0)] || seam_vertex[r.F(f, 1)] || seam_vertex[r.F(f, 2)]) near.push_back(f);
    const EdgeFaces ef = faces_by_edge(r.F, near);
    for (int f : zip_faces[i]) {
      Eigen::Vector3d around = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        const auto it = ef.find(std::minmax(r.F(f, k), r.F(f, (k + 1) % 3)));
        if (it == ef.end()) continue;
        for (int g : it->second)
          if (g != f) around += face_normal(r.V, r.F, g);
      }
      if (face_normal(r.V, r.F, f).dot(around) < 0) ++rep.flipped_faces;
    }
    seam_dihedral_angles(r.V, r.F, zip_faces[i], &rep.dihedral_max_deg, &rep.dihedral_mean_deg);
  }
  return r;
}

}  // namespace mm
