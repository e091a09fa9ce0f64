#include "merge/mesh_merge.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "mesh/mesh.h"
#include "mesh/topology.h"
#include "merge/seam_zip.h"
#include "operators/operators.h"

namespace mm {

namespace {

MergeResult merge_error(StatusCode code, const std::string& message) {
  MergeResult r;
  r.status = Status::error(code, message);
  return r;
}

double ms_since(std::chrono::steady_clock::time_point* t0) {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - *t0).count();
  *t0 = now;
  return ms;
}

struct LoopIndex {
  std::vector<std::vector<int>> loops;
  std::vector<int> loop_of;  // per vertex: loop index or -1
};

LoopIndex index_loops(const Eigen::MatrixXi& F, int n) {
  LoopIndex li;
  li.loops = boundary_loops(F, n);
  li.loop_of.assign(n, -1);
  for (int l = 0; l < static_cast<int>(li.loops.size()); ++l)
    for (int v : li.loops[l])
      if (li.loop_of[v] < 0) li.loop_of[v] = l;
  return li;
}

// The loop of one side of a pair: explicit index or the loop containing the keys.
Status resolve_loop(const LoopIndex& li, const std::vector<int>& keys, int explicit_loop, int nv, const char* side,
                    int pair, int* loop) {
  const std::string where = std::string(side) + " of pair " + std::to_string(pair);
  if (li.loops.empty())
    return Status::error(StatusCode::InvalidMesh, "the " + std::string(side) +
                                                      " mesh has no boundary: cut it open first (meshmorph cut)");
  for (int v : keys)
    if (v < 0 || v >= nv)
      return Status::error(StatusCode::InvalidArgument, "key vertex " + std::to_string(v) + " of the " + where +
                                                            " is out of range (the mesh has " + std::to_string(nv) +
                                                            " vertices)");
  if (explicit_loop >= static_cast<int>(li.loops.size()))
    return Status::error(StatusCode::InvalidArgument, "boundary loop " + std::to_string(explicit_loop) + " of the " +
                                                          where + " does not exist (the mesh has " +
                                                          std::to_string(li.loops.size()) + " boundary loops)");
  *loop = explicit_loop >= 0 ? explicit_loop : li.loop_of[keys[0]];
  for (int v : keys) {
    const auto& L = li.loops[std::max(*loop, 0)];
    if (*loop < 0 || std::find(L.begin(), L.end(), v) == L.end())
      return Status::error(StatusCode::InvalidArgument,
                           "key vertex " + std::to_string(v) + " of the " + where + " is not on " +
                               (*loop < 0 ? std::string("a boundary loop")
                                          : "boundary loop " + std::to_string(*loop) +
                                                (explicit_loop >= 0 ? "" : " (the loop of its first key)")));
  }
  if (li.loops[*loop].size() < 3)
    return Status::error(StatusCode::InvalidMesh, "boundary loop " + std::to_string(*loop) + " of the " + where +
                                                      " has fewer than 3 vertices");
  return Status::success();
}

Eigen::Matrix3d frame(const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal) {
  Eigen::Matrix3d Fm;
  const Eigen::Vector3d e1 = tangent.normalized();
  Eigen::Vector3d e2 = normal - normal.dot(e1) * e1;
  if (!(e2.norm() > 1e-12)) e2 = e1.unitOrthogonal();
  e2.normalize();
  Fm.col(0) = e1;
  Fm.col(1) = e2;
  Fm.col(2) = e1.cross(e2);
  return Fm;
}

// One pair after resolution: the loops in merge order, rotated to start at the first key.
struct Pair {
  int tloop = -1, sloop = -1;
  std::vector<int> t;         // target loop (its own orientation), t[0] = first key
  std::vector<int> s;         // source loop reversed (runs along t), s[0] = partner of t[0]
  std::vector<int> tk, sk;    // key positions in t and s, increasing, tk[0] = sk[0] = 0
  // Per s vertex: target position on the t polyline (edge t[e]→t[e+1], parameter tau).
  std::vector<Eigen::Vector3d> target;
  std::vector<int> edge;
  std::vector<double> tau;
};

std::vector<int> rotated(const std::vector<int>& loop, int start) {
  std::vector<int> out(loop.size());
  for (size_t k = 0; k < loop.size(); ++k) out[k] = loop[(start + k) % loop.size()];
  return out;
}

// Key order along both loops; t and s rotated to start at the first key (Sec. 5.1: curve
// parameterization between consecutive keys).
Status order_keys(const MergeBoundaryPair& in, int index, const std::vector<int>& tloop, const std::vector<int>& sloop,
                  Pair* p) {
  std::vector<int> srev(sloop.rbegin(), sloop.rend());
  const int K = static_cast<int>(in.target_keys.size());
  const int mt = static_cast<int>(tloop.size()), ms = static_cast<int>(srev.size());
  std::vector<int> tpos(K), spos(K);
  for (int k = 0; k < K; ++k) {
    tpos[k] = static_cast<int>(std::find(tloop.begin(), tloop.end(), in.target_keys[k]) - tloop.begin());
    spos[k] = static_cast<int>(std::find(srev.begin(), srev.end(), in.source_keys[k]) - srev.begin());
  }
  std::vector<int> order(K);
  for (int k = 0; k < K; ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return tpos[a] < tpos[b]; });
  const std::string where = " of pair " + std::to_string(index);
  for (int k = 1; k < K; ++k)
    if (tpos[order[k]] == tpos[order[k - 1]])
      return Status::error(StatusCode::InvalidArgument, "target key vertex " + std::to_string(in.target_keys[order[k]]) +
                                                            " is used twice" + where);
  const int s0 = spos[order[0]];
  int last = -1;
  for (int k = 0; k < K; ++k) {
    const int rel = (spos[order[k]] - s0 + ms) % ms;
    if (rel <= last)
      return Status::error(StatusCode::InvalidArgument,
                           "keys are out of order along the loops" + where +
                               ": going along the target loop, the source keys must come in the same order "
                               "along the source loop (traversed so that the merged faces keep one orientation); "
                               "source key " +
                               std::to_string(in.source_keys[order[k]]) + " is out of place");
    last = rel;
  }
  const int t0 = tpos[order[0]];
  p->t = rotated(tloop, t0);
  p->s = rotated(srev, s0);
  for (int k = 0; k < K; ++k) {
    p->tk.push_back((tpos[order[k]] - t0 + mt) % mt);
    p->sk.push_back((spos[order[k]] - s0 + ms) % ms);
  }
  return Status::success();
}

// Arc-length parameterization between consecutive keys: every source loop vertex gets the
// point at the same fraction of arc length on the matching target segment.
Status correspond(const Eigen::MatrixXd& Vt, const Eigen::MatrixXd& Vs, Pair* p) {
  const int mt = static_cast<int>(p->t.size()), ms = static_cast<int>(p->s.size());
  const int K = static_cast<int>(p->tk.size());
  p->target.assign(ms, Eigen::Vector3d::Zero());
  p->edge.assign(ms, 0);
  p->tau.assign(ms, 0.0);
  for (int k = 0; k < K; ++k) {
    const int ta = p->tk[k], tb = k + 1 < K ? p->tk[k + 1] : mt;
    const int sa = p->sk[k], sb = k + 1 < K ? p->sk[k + 1] : ms;
    std::vector<double> tl(1, 0.0), sl(1, 0.0);
    for (int e = ta; e < tb; ++e)
      tl.push_back(tl.back() + (Vt.row(p->t[(e + 1) % mt]) - Vt.row(p->t[e])).norm());
    for (int e = sa; e < sb; ++e)
      sl.push_back(sl.back() + (Vs.row(p->s[(e + 1) % ms]) - Vs.row(p->s[e])).norm());
    if (!(tl.back() > 0) || !(sl.back() > 0))
      return Status::error(StatusCode::InvalidMesh, "a boundary segment between two keys has zero length");
    int e = 0;  // current target edge (relative to ta)
    for (int j = sa; j < sb; ++j) {
      const double u = sl[j - sa] / sl.back() * tl.back();
      while (e + 1 < tb - ta && tl[e + 1] <= u) ++e;
      const double len = tl[e + 1] - tl[e];
      const double tau = len > 0 ? std::clamp((u - tl[e]) / len, 0.0, 1.0) : 0.0;
      const int a = p->t[ta + e], b = p->t[(ta + e + 1) % mt];
      p->edge[j] = (ta + e) % mt;
      p->tau[j] = tau;
      p->target[j] = ((1 - tau) * Vt.row(a) + tau * Vt.row(b)).transpose();
    }
  }
  return Status::success();
}

// Vertices whose geodesic distance (along edges) to any of `seeds` is below `radius`.
std::vector<int> geodesic_band(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<int>& seeds,
                               double radius) {
  const int n = static_cast<int>(V.rows());
  const auto adj = vertex_adjacency(F, n);
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  for (int s : seeds) relax_edge_distances(V, adj, s, &dist, radius);
  std::vector<int> band;
  for (int v = 0; v < n; ++v)
    if (dist[v] < radius) band.push_back(v);
  return band;
}

}  // namespace

int refine_boundary_loop(Eigen::MatrixXd* V, Eigen::MatrixXi* F, std::vector<int>* loop, int min_vertices) {
  const int m0 = static_cast<int>(loop->size());
  if (m0 < 2 || m0 >= min_vertices) return 0;
  // Face of each directed boundary edge loop[k] → loop[k+1].
  std::unordered_map<long long, int> face_of;
  const long long N = V->rows() + (min_vertices - m0) + 1;
  auto key = [&](int a, int b) { return static_cast<long long>(a) * N + b; };
  for (int f = 0; f < F->rows(); ++f)
    for (int c = 0; c < 3; ++c) face_of.emplace(key((*F)(f, c), (*F)(f, (c + 1) % 3)), f);
  std::vector<int> L = *loop;
  std::vector<int> edge_face(L.size(), -1);
  for (size_t k = 0; k < L.size(); ++k) {
    auto it = face_of.find(key(L[k], L[(k + 1) % L.size()]));
    if (it != face_of.end()) edge_face[k] = it->second;
  }
  std::vector<Eigen::RowVector3d> newV;
  const int nv0 = static_cast<int>(V->rows());
  auto pos = [&](int v) -> Eigen::RowVector3d { return v < nv0 ? Eigen::RowVector3d(V->row(v)) : newV[v - nv0]; };
  Eigen::MatrixXi& Fm = *F;
  std::vector<Eigen::RowVector3i> faces(Fm.rows());
  for (int f = 0; f < Fm.rows(); ++f) faces[f] = Fm.row(f);
  while (static_cast<int>(L.size()) < min_vertices) {
    // Longest boundary edge that has a face (ties: first along the loop).
    int best = -1;
    double best_len = -1;
    for (size_t k = 0; k < L.size(); ++k) {
      if (edge_face[k] < 0) continue;
      const double len = (pos(L[k]) - pos(L[(k + 1) % L.size()])).squaredNorm();
      if (len > best_len) {
        best_len = len;
        best = static_cast<int>(k);
      }
    }
    if (best < 0) break;
    const int a = L[best], b = L[(best + 1) % L.size()], f = edge_face[best];
    Eigen::RowVector3i tri = faces[f];
    int c = 0;
    while (!(tri[c] == a && tri[(c + 1) % 3] == b)) ++c;
    const int opp = tri[(c + 2) % 3];
    const int m = nv0 + static_cast<int>(newV.size());
    newV.push_back(0.5 * (pos(a) + pos(b)));
    faces[f] = Eigen::RowVector3i(a, m, opp);
    faces.emplace_back(m, b, opp);
    const int g = static_cast<int>(faces.size()) - 1;
    L.insert(L.begin() + best + 1, m);
    edge_face[best] = f;
    edge_face.insert(edge_face.begin() + best + 1, g);
  }
  V->conservativeResize(nv0 + static_cast<int>(newV.size()), 3);
  for (size_t k = 0; k < newV.size(); ++k) V->row(nv0 + static_cast<Eigen::Index>(k)) = newV[k];
  Fm.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) Fm.row(static_cast<Eigen::Index>(f)) = faces[f];
  *loop = L;
  return static_cast<int>(newV.size());
}

MergeResult merge_meshes(const MergeInput& in, const MergeOptions& opt, const Progress& progress) {
  auto clock = std::chrono::steady_clock::now();
  // ---- options and inputs
  if (!(opt.gradient_weight > 0) || !std::isfinite(opt.gradient_weight))
    return merge_error(StatusCode::InvalidArgument, "merge: gradient_weight must be a positive number");
  if (!(opt.refine_ratio == 0 || opt.refine_ratio >= 1) || !std::isfinite(opt.refine_ratio))
    return merge_error(StatusCode::InvalidArgument, "merge: refine_ratio must be 0 (off) or at least 1");
  if (opt.smoothing_iterations < 0 || opt.smoothing_iterations > 1000 || opt.smoothing_rings < 0 ||
      opt.smoothing_rings > 20 || !(opt.smoothing_step >= 0 && opt.smoothing_step <= 1))
    return merge_error(StatusCode::InvalidArgument,
                       "merge: smoothing_iterations must be 0..1000, smoothing_rings 0..20, smoothing_step in [0, 1]");
  if (!(opt.transition_target_width >= 0 && opt.transition_source_width >= 0) ||
      !std::isfinite(opt.transition_target_width + opt.transition_source_width) ||
      ((opt.transition_target_width > 0) != (opt.transition_source_width > 0)))
    return merge_error(StatusCode::InvalidArgument,
                       "merge: transition widths must both be positive (transition regions on) or both 0 (off)");
  if (!(opt.roi_width > 0))
    return merge_error(StatusCode::InvalidArgument, "merge: roi_width must be positive");
  const bool dependent = opt.mode == MergeMode::ConfigurationDependent;
  if (!dependent && !in.source_fixed.empty())
    return merge_error(StatusCode::InvalidArgument,
                       "merge: fixed source handles need configuration-dependent mode (the source's placement "
                       "is free in configuration-independent merging)");
  for (const auto* M : {&in.target_V, &in.source_V})
    if (M->rows() == 0 || M->cols() != 3 || !M->allFinite())
      return merge_error(StatusCode::InvalidMesh, "merge: both meshes need vertices with finite coordinates");
  for (const auto* F : {&in.target_F, &in.source_F})
    if (F->rows() == 0 || F->cols() != 3)
      return merge_error(StatusCode::InvalidMesh, "merge: both meshes need triangles");
  const int ntv = static_cast<int>(in.target_V.rows());
  for (const auto& [F, n, name] : {std::make_tuple(&in.target_F, ntv, "target"),
                                   std::make_tuple(&in.source_F, static_cast<int>(in.source_V.rows()), "source")})
    if (F->minCoeff() < 0 || F->maxCoeff() >= n)
      return merge_error(StatusCode::InvalidMesh, std::string("merge: a ") + name + " face index is out of range");
  if (in.pairs.empty()) return merge_error(StatusCode::InvalidArgument, "merge: no boundary pair given");

  Eigen::MatrixXd Vs = in.source_V;
  Eigen::MatrixXi Fs = in.source_F;
  const LoopIndex tl = index_loops(in.target_F, ntv);
  LoopIndex sl = index_loops(Fs, static_cast<int>(Vs.rows()));
  const int P = static_cast<int>(in.pairs.size());
  std::vector<Pair> pairs(P);
  std::vector<std::vector<int>> sloops(P);
  MergeResult out;
  for (int i = 0; i < P; ++i) {
    const MergeBoundaryPair& bp = in.pairs[i];
    if (bp.target_keys.size() != bp.source_keys.size())
      return merge_error(StatusCode::InvalidArgument, "merge: pair " + std::to_string(i) + " has " +
                                                          std::to_string(bp.target_keys.size()) + " target keys but " +
                                                          std::to_string(bp.source_keys.size()) + " source keys");
    if (bp.target_keys.size() < 2)
      return merge_error(StatusCode::InvalidArgument, "merge: pair " + std::to_string(i) +
                                                          " needs at least two key vertex pairs (Sec. 5.1)");
    if (Status s = resolve_loop(tl, bp.target_keys, bp.target_loop, ntv, "target", i, &pairs[i].tloop); !s.ok())
      return merge_error(s.code, "merge: " + s.message);
    if (Status s = resolve_loop(sl, bp.source_keys, bp.source_loop, static_cast<int>(Vs.rows()), "source", i,
                                &pairs[i].sloop);
        !s.ok())
      return merge_error(s.code, "merge: " + s.message);
    for (int j = 0; j < i; ++j)
      if (pairs[j].tloop == pairs[i].tloop || pairs[j].sloop == pairs[i].sloop)
        return merge_error(StatusCode::InvalidArgument, "merge: pairs " + std::to_string(j) + " and " +
                                                            std::to_string(i) + " use the same boundary loop");
    sloops[i] = sl.loops[pairs[i].sloop];
  }
  // ---- Sec. 6: refine source loops much coarser than their target loop.
  for (int i = 0; i < P; ++i) {
    const int mt = static_cast<int>(tl.loops[pairs[i].tloop].size());
    if (opt.refine_ratio >= 1 && mt > opt.refine_ratio * static_cast<double>(sloops[i].size()))
      out.stats.refined_vertices += refine_boundary_loop(&Vs, &Fs, &sloops[i], mt);
  }
  const int nsv = static_cast<int>(Vs.rows());
  for (int i = 0; i < P; ++i) {
    if (Status s = order_keys(in.pairs[i], i, tl.loops[pairs[i].tloop], sloops[i], &pairs[i]); !s.ok())
      return merge_error(s.code, "merge: " + s.message);
    if (Status s = correspond(in.target_V, Vs, &pairs[i]); !s.ok()) return merge_error(s.code, "merge: " + s.message);
  }
  if (!progress.update("merge: boundary constraints", 0.05)) {
    out.status = cancelled_status("merge");
    return out;
  }

  // ---- Boundary constraints (Sec. 5.1 / 5.2): one single-vertex handle per source loop vertex
  // with x ↦ s_i R_i (x − v_i) + u_i, i.e. position u_i and deformation gradient M_i = R_i S_i.
  const Eigen::MatrixXd Nt = vertex_normals(in.target_V, in.target_F);
  const Eigen::MatrixXd Ns = vertex_normals(Vs, Fs);
  EditRegion region;
  std::vector<HandleTransform> transforms;
  std::vector<char> on_seam(nsv, 0);
  for (const Pair& p : pairs) {
    const int ms = static_cast<int>(p.s.size());
    for (int j = 0; j < ms; ++j) {
      const int v = p.s[j], prev = p.s[(j + ms - 1) % ms], next = p.s[(j + 1) % ms];
      const Eigen::Vector3d ts = (Vs.row(next) - Vs.row(prev)).transpose();
      const Eigen::Vector3d tt = p.target[(j + 1) % ms] - p.target[(j + ms - 1) % ms];
      const int a = p.t[p.edge[j]], b = p.t[(p.edge[j] + 1) % p.t.size()];
      Eigen::Vector3d nt = ((1 - p.tau[j]) * Nt.row(a) + p.tau[j] * Nt.row(b)).transpose();
      if (!(nt.norm() > 1e-12)) nt = Nt.row(a).transpose();
      const double s = ts.norm() > 0 ? tt.norm() / ts.norm() : 1.0;
      Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
      if (!dependent && ts.norm() > 0 && tt.norm() > 0)
        R = frame(tt, nt) * frame(ts, Ns.row(v).transpose()).transpose();
      HandleTransform T;
      T.linear = s * R;
      T.translation = p.target[j] - T.linear * Vs.row(v).transpose();
      region.handles.push_back({v});
      transforms.push_back(T);
      on_seam[v] = 1;
    }
  }
  out.stats.boundary_constraints = static_cast<int>(region.handles.size());
  if (dependent) {
    for (int v : in.source_fixed) {
      if (v < 0 || v >= static_cast<int>(in.source_V.rows()))
        return merge_error(StatusCode::InvalidArgument, "merge: fixed source vertex " + std::to_string(v) +
                                                            " is out of range");
      if (on_seam[v])
        return merge_error(StatusCode::InvalidArgument, "merge: fixed source vertex " + std::to_string(v) +
                                                            " is on a merged boundary");
      region.fixed.push_back(v);
    }
    std::vector<int> seeds;
    for (int v = 0; v < nsv; ++v)
      if (on_seam[v]) seeds.push_back(v);
    region.roi = geodesic_band(Vs, Fs, seeds, opt.roi_width * bounding_box_diagonal(Vs));
  }
  LaplacianEditOptions eopt = opt.editor;
  eopt.gradient_constraint_weight = opt.gradient_weight;
  eopt.handle_basis = false;
  eopt.method = EditMethod::Implicit;
  LaplacianEditor editor;
  if (Status s = editor.precompute(Vs, Fs, region, eopt, progress.sub(0.05, 0.7)); !s.ok())
    return merge_error(s.code, "merge: " + s.message);
  out.stats.editor = editor.stats();
  out.stats.precompute_ms = ms_since(&clock);
  EditResult d = editor.drag(transforms);
  if (!d.status.ok()) return merge_error(d.status.code, "merge: " + d.status.message);
  EditResult fin = editor.finalize(FeatureSize::Scale);  // Eq. 10: the feature scales follow s_i
  if (!fin.status.ok()) return merge_error(fin.status.code, "merge: " + fin.status.message);
  out.stats.solve_ms = ms_since(&clock);
  if (!progress.update("merge: zip", 0.8)) {
    out.status = cancelled_status("merge");
    return out;
  }
  out.source_deformed = fin.V;
  out.source_F = Fs;
  out.stats.source_vertices = nsv;
  out.stats.target_vertices = ntv;
  // The boundary vertices sit exactly on their target positions (hard constraints).
  for (const Pair& p : pairs)
    for (size_t j = 0; j < p.s.size(); ++j) out.source_deformed.row(p.s[j]) = p.target[j].transpose();

  // ---- Zip (Sec. 5.1).
  std::vector<SeamCurves> seams(P);
  for (int i = 0; i < P; ++i) {
    seams[i].target_loop = pairs[i].t;
    seams[i].source_loop = pairs[i].s;
  }
  ZipOptions zopt;
  zopt.enabled = opt.zip;
  zopt.smoothing_iterations = opt.smoothing_iterations;
  zopt.smoothing_rings = opt.smoothing_rings;
  zopt.smoothing_step = opt.smoothing_step;
  const double tdiag = bounding_box_diagonal(in.target_V);
  zopt.transition_target_width = opt.transition_target_width * tdiag;
  zopt.transition_source_width = opt.transition_source_width * tdiag;
  ZipResult z = zip_meshes(in.target_V, in.target_F, out.source_deformed, Fs, seams, zopt);
  if (!z.status.ok()) return merge_error(z.status.code, "merge: " + z.status.message);
  out.V = std::move(z.V);
  out.F = std::move(z.F);
  out.target_map = std::move(z.target_map);
  out.source_offset = z.source_offset;
  out.stats.seams = std::move(z.seams);
  out.stats.transition_vertices = z.transition_vertices;
  out.stats.zip_ms = ms_since(&clock);
  if (!out.V.allFinite()) return merge_error(StatusCode::NumericalError, "merge: the result has non-finite positions");
  progress.update("merge: done", 1.0);
  return out;
}

}  // namespace mm
