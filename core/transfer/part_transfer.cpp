#include "transfer/part_transfer.h"
#include "transfer/flip_repair.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>
#include <numeric>

#include <Eigen/Geometry>

#include "cage/enclosing_cage.h"
#include "common/threads.h"
#include "linalg/rigid_fit.h"
#include "merge/cut.h"
#include "mesh/butterfly.h"
#include "mesh/topology.h"
#include "metrics/transfer_metrics.h"
#include "operators/operators.h"
#include "spatial/self_intersections.h"

namespace mm {

namespace part_detail {

double part_ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// A part as a submesh: faces of F with all three vertices in the set, compacted.
struct PartMesh {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  std::vector<int> from;      // submesh vertex → mesh vertex
  std::vector<int> boundary;  // submesh vertices on its boundary loops (the cut), ascending
  int tip = -1;               // submesh vertex farthest (along edges) from the boundary
};

PartMesh part_submesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<int>& set) {
  std::vector<char> in(V.rows(), 0);
  for (int v : set) in[v] = 1;
  std::vector<int> faces;
  for (int f = 0; f < F.rows(); ++f)
    if (in[F(f, 0)] && in[F(f, 1)] && in[F(f, 2)]) faces.push_back(f);
  Eigen::MatrixXi Fs(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t k = 0; k < faces.size(); ++k) Fs.row(static_cast<Eigen::Index>(k)) = F.row(faces[k]);
  PartMesh p;
  compact_mesh(V, Fs, &p.V, &p.F, &p.from);
  const int n = static_cast<int>(p.V.rows());
  if (n == 0) return p;
  for (const auto& loop : boundary_loops(p.F, n))
    for (int v : loop) p.boundary.push_back(v);
  std::sort(p.boundary.begin(), p.boundary.end());
  p.boundary.erase(std::unique(p.boundary.begin(), p.boundary.end()), p.boundary.end());
  if (!p.boundary.empty()) {
    const auto adj = vertex_adjacency(p.F, n);
    std::vector<double> d(n, std::numeric_limits<double>::infinity());
    for (int b : p.boundary) relax_edge_distances(p.V, adj, b, &d);
    double best = -1;
    for (int v = 0; v < n; ++v)
      if (std::isfinite(d[v]) && d[v] > best) best = d[v], p.tip = v;
  }
  return p;
}

// Local frame of Sec. 4.3 (columns e1, e2, e3) from the average point o of the submesh, the
// average b of its cut-boundary vertices and the point f farthest from the boundary: e1 along
// b → f, e2 the part of b → o orthogonal to it. *axis_only when o lies on the axis (a straight
// limb): then only e1 is meaningful.
Eigen::Matrix3d part_frame(const Eigen::MatrixXd& P, const std::vector<int>& boundary, int tip, bool* axis_only) {
  const Eigen::Vector3d o = P.colwise().mean().transpose();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (int v : boundary) b += P.row(v).transpose();
  b /= std::max<size_t>(1, boundary.size());
  const Eigen::Vector3d f = P.row(tip).transpose();
  Eigen::Vector3d e1 = f - b;
  const double len = e1.norm();
  e1 = len > 0 ? Eigen::Vector3d(e1 / len) : Eigen::Vector3d::UnitX();
  Eigen::Vector3d e2 = (o - b) - (o - b).dot(e1) * e1;
  *axis_only = !(e2.norm() > 0.05 * std::max(len, (o - b).norm()));
  if (*axis_only) e2 = e1.unitOrthogonal();
  e2.normalize();
  Eigen::Matrix3d E;
  E.col(0) = e1;
  E.col(1) = e2;
  E.col(2) = e1.cross(e2);
  return E;
}

Eigen::Vector3d part_boundary_centroid(const Eigen::MatrixXd& P, const std::vector<int>& boundary) {
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (int v : boundary) b += P.row(v).transpose();
  return b / std::max<size_t>(1, boundary.size());
}

bool part_regions_equal(const PartRegion& a, const PartRegion& b) {
  if (a.kind != b.kind) return false;
  switch (a.kind) {
    case PartRegionKind::Disk: return a.seed == b.seed && a.radius == b.radius;
    case PartRegionKind::Plane: return a.point == b.point && a.normal == b.normal && a.keep == b.keep;
    case PartRegionKind::Vertices: return a.vertices == b.vertices;
  }
  return false;
}

// Dihedral angle change (degrees) across the edges that join a part to the rest of the mesh:
// |θ_A(e) − θ_B(e)| with θ the angle between the two face normals; mean and max over those edges.
void part_seam_dihedral(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXi& F,
                        const std::vector<char>& in_part, double* mean, double* max) {
  const Eigen::MatrixXd NA = face_normals(A, F), NB = face_normals(B, F);
  std::vector<std::pair<std::pair<int, int>, int>> uses;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (in_part[a] != in_part[b]) uses.push_back({{std::min(a, b), std::max(a, b)}, f});
    }
  std::sort(uses.begin(), uses.end());
  double sum = 0, mx = 0;
  int count = 0;
  for (size_t i = 0; i + 1 < uses.size(); ++i) {
    if (uses[i].first != uses[i + 1].first) continue;
    if (i + 2 < uses.size() && uses[i + 2].first == uses[i].first) continue;  // non-manifold edge
    const int f = uses[i].second, g = uses[i + 1].second;
    auto angle = [](const Eigen::RowVector3d& n1, const Eigen::RowVector3d& n2) {
      return std::atan2(n1.cross(n2).norm(), n1.dot(n2)) * 180.0 / M_PI;
    };
    const double d = std::abs(angle(NA.row(f), NA.row(g)) - angle(NB.row(f), NB.row(g)));
    sum += d;
    mx = std::max(mx, d);
    ++count;
  }
  *mean = count > 0 ? sum / count : 0;
  *max = mx;
}

// Isoline perimeters of the geodesic distance from `tip` and the radius of the narrowest neck
// (see header): 0 when no cut fits between `r_min`, `r_max` (0 = no bound) and the area cap.
double part_neck_radius(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                        const std::vector<std::vector<int>>& adj, int tip, double r_min, double r_max,
                        const PartTransferOptions& opt) {
  const int n = static_cast<int>(V.rows());
  std::vector<double> d(n, std::numeric_limits<double>::infinity());
  relax_edge_distances(V, adj, tip, &d);
  double dmax = 0;
  for (double x : d)
    if (std::isfinite(x)) dmax = std::max(dmax, x);
  if (!(dmax > 0)) return 0;
  const int N = 160;
  std::vector<double> perim(N, 0), area(N, 0);
  double total = 0;
  auto level = [&](int k) { return dmax * (k + 1) / (N + 1); };
  for (int f = 0; f < F.rows(); ++f) {
    const int i0 = F(f, 0), i1 = F(f, 1), i2 = F(f, 2);
    if (!std::isfinite(d[i0]) || !std::isfinite(d[i1]) || !std::isfinite(d[i2])) continue;
    const Eigen::Vector3d p[3] = {V.row(i0).transpose(), V.row(i1).transpose(), V.row(i2).transpose()};
    const double dv[3] = {d[i0], d[i1], d[i2]};
    const double fa = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    total += fa;
    const double lo = std::min({dv[0], dv[1], dv[2]}), hi = std::max({dv[0], dv[1], dv[2]});
    // Area inside level k: the whole face once its farthest corner is inside.
    const int k_in = static_cast<int>(std::ceil(hi * (N + 1) / dmax)) - 1;
    if (k_in < N) area[std::max(0, k_in)] += fa;
    for (int k = std::max(0, static_cast<int>(std::floor(lo * (N + 1) / dmax)) - 1); k < N; ++k) {
      const double t = level(k);
      if (t >= hi) break;
      if (t <= lo) continue;
      Eigen::Vector3d pts[2];
      int m = 0;
      for (int e = 0; e < 3 && m < 2; ++e) {
        const double a = dv[e], b = dv[(e + 1) % 3];
        if ((a < t) != (b < t)) {
          const double s = (t - a) / (b - a);
          pts[m++] = p[e] + s * (p[(e + 1) % 3] - p[e]);
        }
      }
      if (m == 2) perim[k] += (pts[0] - pts[1]).norm();
    }
  }
  for (int k = 1; k < N; ++k) area[k] += area[k - 1];
  int k_lo = -1, k_hi = -1;
  for (int k = 0; k < N; ++k) {
    if (area[k] > opt.max_part_area * total || (r_max > 0 && level(k) > r_max)) break;
    k_hi = k;
    if (k_lo < 0 && level(k) >= r_min && area[k] >= 0.01 * total && perim[k] > 0) k_lo = k;
  }
  if (k_lo < 0 || k_hi < k_lo) return 0;
  // The window ends where the isoline grows past neck_ratio × the narrowest one so far.
  int k_end = k_hi;
  double m = perim[k_lo];
  for (int k = k_lo; k <= k_hi; ++k) {
    m = std::min(m, perim[k]);
    if (perim[k] > opt.neck_ratio * m) {
      k_end = k - 1;
      break;
    }
  }
  // Narrowest isoline in the window; the latest of those within 10% of it (closest to the body).
  double best = std::numeric_limits<double>::infinity();
  for (int k = k_lo; k <= k_end; ++k) best = std::min(best, perim[k]);
  int k_cut = k_lo;
  for (int k = k_lo; k <= k_end; ++k)
    if (perim[k] <= 1.1 * best) k_cut = k;
  return level(k_cut);
}

// Landmarks of a different-connectivity part pair (header, step 3): pairs inside both parts,
// the tips, and 6 samples of the cut loops matched by position after centring the loops.
std::vector<LandmarkPair> part_landmarks(const PartMesh& R, const PartMesh& S, const std::vector<LandmarkPair>& level,
                                         int n_ref, int n_src) {
  std::vector<int> rmap(n_ref, -1), smap(n_src, -1);
  for (int i = 0; i < static_cast<int>(R.from.size()); ++i) rmap[R.from[i]] = i;
  for (int i = 0; i < static_cast<int>(S.from.size()); ++i) smap[S.from[i]] = i;
  std::vector<LandmarkPair> out;
  std::vector<char> used_r(R.V.rows(), 0), used_s(S.V.rows(), 0);
  auto add = [&](int r, int s) {
    if (r < 0 || s < 0 || used_r[r] || used_s[s]) return;
    used_r[r] = used_s[s] = 1;
    out.push_back({r, s});
  };
  for (const LandmarkPair& p : level)
    if (p.reference >= 0 && p.reference < n_ref && p.source >= 0 && p.source < n_src)
      add(rmap[p.reference], smap[p.source]);
  add(R.tip, S.tip);
  const auto rl = boundary_loops(R.F, static_cast<int>(R.V.rows()));
  const auto sl = boundary_loops(S.F, static_cast<int>(S.V.rows()));
  auto largest = [](const std::vector<std::vector<int>>& loops) {
    size_t best = 0;
    for (size_t i = 1; i < loops.size(); ++i)
      if (loops[i].size() > loops[best].size()) best = i;
    return best;
  };
  if (!rl.empty() && !sl.empty()) {
    const auto& lr = rl[largest(rl)];
    const auto& ls = sl[largest(sl)];
    Eigen::RowVector3d cr = Eigen::RowVector3d::Zero(), cs = Eigen::RowVector3d::Zero();
    for (int v : lr) cr += R.V.row(v);
    for (int v : ls) cs += S.V.row(v);
    cr /= lr.size();
    cs /= ls.size();
    // Both loops follow their faces' orientation, so they run the same way around the cut: match
    // the first sample by position (loops centred), then step both by equal arc fractions.
    const int samples = 6;
    int r0 = 0;
    double bd = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < lr.size(); ++i) {
      const double dd = ((R.V.row(lr[i]) - cr) - (S.V.row(ls[0]) - cs)).squaredNorm();
      if (dd < bd) bd = dd, r0 = static_cast<int>(i);
    }
    for (int k = 0; k < samples; ++k)
      add(lr[(r0 + lr.size() * k / samples) % lr.size()], ls[(ls.size() * k) / samples]);
  }
  return out;
}

// Same regions, names aside (proposals of two neck windows often coincide).
bool part_lists_equal(const std::vector<PartPair>& a, const std::vector<PartPair>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!part_regions_equal(a[i].source, b[i].source) || !part_regions_equal(a[i].reference, b[i].reference) ||
        !part_lists_equal(a[i].children, b[i].children))
      return false;
  return true;
}

bool part_specs_equal(const PartsSpec& a, const PartsSpec& b) { return part_lists_equal(a.parts, b.parts); }

}  // namespace part_detail

using namespace part_detail;

Status part_vertices(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const PartRegion& region,
                     std::vector<int>* vertices) {
  vertices->clear();
  const int n = static_cast<int>(V.rows());
  switch (region.kind) {
    case PartRegionKind::Vertices:
      for (int v : region.vertices) {
        if (v < 0 || v >= n)
          return Status::error(StatusCode::InvalidArgument, "part vertex " + std::to_string(v) +
                                                                " is out of range (the mesh has " + std::to_string(n) +
                                                                " vertices)");
        vertices->push_back(v);
      }
      break;
    case PartRegionKind::Disk: {
      if (region.seed < 0 || region.seed >= n)
        return Status::error(StatusCode::InvalidArgument, "part seed vertex " + std::to_string(region.seed) +
                                                              " is out of range (the mesh has " + std::to_string(n) +
                                                              " vertices)");
      if (!(region.radius > 0) || !std::isfinite(region.radius))
        return Status::error(StatusCode::InvalidArgument, "part disk radius must be > 0 (fraction of the diagonal)");
      // The part is what cut_disk removes: every vertex the kept piece no longer references.
      const CutResult c = cut_disk(V, F, region.seed, region.radius * bounding_box_diagonal(V));
      if (!c.status.ok()) return Status::error(StatusCode::InvalidArgument, "part disk: " + c.status.message);
      std::vector<char> kept(n, 0);
      for (int v : c.from)
        if (v >= 0) kept[v] = 1;
      for (int v = 0; v < n; ++v)
        if (!kept[v]) vertices->push_back(v);
      break;
    }
    case PartRegionKind::Plane: {
      PlaneCutOptions po;
      po.snap_fraction = 0;  // keep vertex positions: the part is a vertex set of the input
      const CutResult c = cut_plane(V, F, region.point, region.normal, region.keep, po);
      if (!c.status.ok()) return Status::error(StatusCode::InvalidArgument, "part plane: " + c.status.message);
      for (int v : c.from)
        if (v >= 0) vertices->push_back(v);
      break;
    }
  }
  std::sort(vertices->begin(), vertices->end());
  vertices->erase(std::unique(vertices->begin(), vertices->end()), vertices->end());
  if (vertices->empty()) return Status::error(StatusCode::InvalidArgument, "the part region selects no vertex");
  if (static_cast<int>(vertices->size()) >= n)
    return Status::error(StatusCode::InvalidArgument, "the part region selects the whole mesh");
  return Status::success();
}

PartsSpec propose_parts(const Mesh& reference, const Mesh& source, const Eigen::MatrixXd& transferred,
                        const std::vector<LandmarkPair>& landmarks, const PartTransferOptions& opt,
                        std::vector<double>* disagreement) {
  PartsSpec spec;
  const int n = static_cast<int>(source.V.rows());
  const bool same = reference.num_vertices() == source.num_vertices() && reference.F == source.F;
  const double diag_ref = bounding_box_diagonal(reference.V);
  const double diag_src = bounding_box_diagonal(source.V);
  std::vector<double> d(n, 0.0);
  RigidFitOptions fo;
  fo.scale = true;
  const auto adj_s = vertex_adjacency(source.F, n);
  if (same) {
    // Local pose disagreement: the rotation angle (degrees) of the best rigid fit of each
    // vertex's `disagreement_rings`-ring from the (globally aligned) level-1 result onto the
    // reference. A limb the low frequencies left mis-oriented rotates as a whole, so the angle is
    // high along all of it and falls off at its joint, where the cut belongs.
    const RigidFit fit = fit_rigid(transferred, reference.V, fo);
    const Eigen::MatrixXd aligned = (fit.s * transferred * fit.R.transpose()).rowwise() + fit.t.transpose();
    for (int i = 0; i < n; ++i) {
      const std::vector<int> ring = k_ring(adj_s, i, opt.disagreement_rings);
      if (ring.size() < 4) continue;
      Eigen::MatrixXd A(ring.size(), 3), B(ring.size(), 3);
      for (size_t k = 0; k < ring.size(); ++k) {
        A.row(static_cast<Eigen::Index>(k)) = aligned.row(ring[k]);
        B.row(static_cast<Eigen::Index>(k)) = reference.V.row(ring[k]);
      }
      RigidFitOptions ro;
      ro.min_spread = 0.05;  // a nearly collinear ring has no well-defined rotation
      const RigidFit local = fit_rigid(A, B, ro);
      d[i] = local.degenerate ? 0.0 : Eigen::AngleAxisd(local.R).angle() * 180.0 / M_PI;
    }
    // Two passes of 1-ring averaging: single vertices with an ill-conditioned ring (a flat ear
    // tip can flip its best rotation by 180°) do not become seeds.
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<double> sm(n, 0.0);
      for (int i = 0; i < n; ++i) {
        double sum = d[i];
        for (int w : adj_s[i]) sum += d[w];
        sm[i] = sum / (1 + adj_s[i].size());
      }
      d.swap(sm);
    }
  } else if (!landmarks.empty()) {
    // Only the landmark pairs correspond: their distance after a similarity fit, in degrees of
    // the same scale (1 degree per 1/180 of the diagonal) so that one threshold serves both.
    Eigen::MatrixXd P(landmarks.size(), 3), Q(landmarks.size(), 3);
    for (size_t k = 0; k < landmarks.size(); ++k) {
      P.row(static_cast<Eigen::Index>(k)) = transferred.row(landmarks[k].source);
      Q.row(static_cast<Eigen::Index>(k)) = reference.V.row(landmarks[k].reference);
    }
    const RigidFit fit = fit_rigid(P, Q, fo);
    for (size_t k = 0; k < landmarks.size(); ++k)
      d[landmarks[k].source] = 180.0 * (fit.s * fit.R * P.row(static_cast<Eigen::Index>(k)).transpose() + fit.t -
                                        Q.row(static_cast<Eigen::Index>(k)).transpose()).norm() / diag_ref;
  }
  if (disagreement) *disagreement = d;
  const auto adj_r = same ? std::vector<std::vector<int>>{} : vertex_adjacency(reference.F, reference.num_vertices());
  const Eigen::VectorXd a = mass_diagonal(source.V, source.F);
  const Eigen::RowVector3d centroid = (a.transpose() * source.V) / std::max(a.sum(), 1e-300);
  std::vector<char> taken(n, 0);
  for (int p = 0; p < opt.max_parts; ++p) {
    int worst = -1;
    for (int i = 0; i < n; ++i)
      if (!taken[i] && (worst < 0 || d[i] > d[worst])) worst = i;
    if (worst < 0 || !(d[worst] >= opt.min_disagreement)) break;
    // Tip and the geodesic extent of the high-disagreement region.
    int tip = worst, tip_ref = -1;
    std::vector<int> blob{worst};
    if (same) {
      std::vector<char> seen(n, 0);
      seen[worst] = 1;
      for (size_t q = 0; q < blob.size(); ++q)
        for (int w : adj_s[blob[q]])
          if (!seen[w] && !taken[w] && d[w] >= opt.blob_fraction * d[worst]) {
            seen[w] = 1;
            blob.push_back(w);
          }
      double far = -1;
      for (int v : blob) {
        const double r = (source.V.row(v) - centroid).norm();
        if (r > far) far = r, tip = v;
      }
      tip_ref = tip;
    } else {
      for (const LandmarkPair& l : landmarks)
        if (l.source == worst) tip_ref = l.reference;
    }
    double r_blob = 0;
    std::vector<double> dt(n, std::numeric_limits<double>::infinity());
    relax_edge_distances(source.V, adj_s, tip, &dt);
    for (int v : blob) r_blob = std::max(r_blob, dt[v]);
    if (!same) {
      // Different connectivity: only landmarks tell where the pose agrees again. The high-
      // disagreement region is taken to reach halfway to the nearest landmark that agrees
      // (below blob_fraction × the worst); without one, the neck window is open.
      double agree = std::numeric_limits<double>::infinity();
      for (const LandmarkPair& l : landmarks)
        if (d[l.source] < opt.blob_fraction * d[worst]) agree = std::min(agree, dt[l.source]);
      if (std::isfinite(agree)) r_blob = 0.5 * agree;
    }
    const double radius = part_neck_radius(source.V, source.F, adj_s, tip, opt.neck_window_begin * r_blob,
                                           opt.neck_window_end * r_blob, opt);
    // Mark the region (and what the disk would cover) taken either way, so the next proposal
    // looks elsewhere.
    for (int v : blob) taken[v] = 1;
    for (int v = 0; v < n; ++v)
      if (dt[v] < std::max(radius, r_blob) * 1.15) taken[v] = 1;
    if (!(radius > 0) || tip_ref < 0) continue;
    int inside = 0;
    for (int v = 0; v < n; ++v) inside += dt[v] < radius;
    if (inside < opt.min_part_fraction * n) continue;  // too small to carry a pose of its own
    PartPair pp;
    char name[96];
    std::snprintf(name, sizeof name, "auto %d (disagreement %.3f at vertex %d)", p + 1, d[worst], worst);
    pp.name = name;
    pp.source.kind = PartRegionKind::Disk;
    pp.source.seed = tip;
    pp.source.radius = radius / diag_src;
    if (same) {
      pp.reference = pp.source;
    } else {
      const double rr = part_neck_radius(reference.V, reference.F, adj_r, tip_ref, 0, 0, opt);
      if (!(rr > 0)) continue;
      pp.reference.kind = PartRegionKind::Disk;
      pp.reference.seed = tip_ref;
      pp.reference.radius = rr / diag_ref;
    }
    spec.parts.push_back(std::move(pp));
  }
  return spec;
}

namespace {

// Level 1 (opt.transfer, whose own fold retry is off) and the parts on it. *level1_folds (if
// given) is set once level 1 is known to fold, before the parts report progress. With
// `stop_unless_below` ≥ 0, the parts are not run (and *stopped is set) when level 1 has at least
// that many fold violations.
PartTransferResult level_and_parts(const Mesh& reference, const Mesh& source, const std::vector<LandmarkPair>& landmarks,
                                   const PartsSpec* spec, const PartTransferOptions& opt, const Progress& progress,
                                   std::atomic<bool>* level1_folds = nullptr, int stop_unless_below = -1,
                                   bool* stopped = nullptr) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  PartTransferResult out;
  if (opt.seam_rings < 1 || opt.min_part_vertices < 0 || opt.max_subdivisions < 0 || opt.max_subdivisions > 3) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "part transfer: need seam_rings >= 1, min_part_vertices >= 0, max_subdivisions in 0..3");
    return out;
  }
  // Level 1: the whole body (its flips are repaired with the parts: in the gate and at the end).
  PoseTransferOptions level1_opt = opt.transfer;
  level1_opt.flip_repair_rings = 0;
  out.level1 = pose_transfer(reference, source, landmarks, level1_opt, progress.sub(0.0, 0.4));
  out.ms_level1 = part_ms_since(t_start);
  if (!(out.status = out.level1.status).ok()) return out;
  out.V_level1 = out.level1.V;
  out.folds_level1 = out.level1.fold_retry.checked ? out.level1.folds : fold_report(reference, source, out.V_level1);
  if (level1_folds) level1_folds->store(out.folds_level1.violations() > 0);
  if (stop_unless_below >= 0 && out.folds_level1.violations() >= stop_unless_below) {
    if (stopped) *stopped = true;
    return out;
  }
  const auto t_parts = clock::now();
  if (!progress.update("part proposals", 0.42)) {
    out.status = cancelled_status("part proposals");
    return out;
  }
  // The part sets to try: the given one, or the proposals on `base` of each neck window that
  // gives a set not seen before (PartTransferOptions::more_proposal_windows).
  auto propose_sets = [&](const Eigen::MatrixXd& base, std::vector<double>* disagreement) {
    std::vector<PartsSpec> sets;
    sets.push_back(propose_parts(reference, source, base, out.level1.landmarks, opt, disagreement));
    for (size_t k = 0; k < opt.more_proposal_windows.size() && static_cast<int>(k) + 1 < opt.proposal_sets; ++k) {
      const PartTransferOptions::ProposalWindow& w = opt.more_proposal_windows[k];
      PartTransferOptions o = opt;
      o.neck_window_begin = w.neck_window_begin, o.neck_window_end = w.neck_window_end, o.max_part_area = w.max_part_area;
      PartsSpec c = propose_parts(reference, source, base, out.level1.landmarks, o);
      if (std::none_of(sets.begin(), sets.end(), [&](const PartsSpec& x) { return part_specs_equal(x, c); }))
        sets.push_back(std::move(c));
    }
    return sets;
  };
  std::vector<PartsSpec> candidates = spec ? std::vector<PartsSpec>{*spec} : propose_sets(out.V_level1, &out.disagreement);
  const int rounds = spec ? 1 : std::max(1, opt.proposal_rounds);

  const int nS = source.num_vertices(), nR = reference.num_vertices();
  const bool same_conn = nS == nR && reference.F == source.F;
  const auto adj_full = vertex_adjacency(source.F, nS);
  // The editor solves only over manifold vertices; a non-manifold one in a seam band is glued
  // as a known vertex instead (TOSCA camel_ref has 3 where its horse part is cut).
  std::vector<char> non_manifold(nS, 0);
  for (const VertexFans& v : non_manifold_vertices(source.F, nS)) non_manifold[v.vertex] = 1;
  std::function<int(const std::vector<PartPair>&)> count_parts = [&](const std::vector<PartPair>& l) {
    int c = 0;
    for (const PartPair& p : l) c += 1 + count_parts(p.children);
    return c;
  };
  int round = 1;
  // One candidate set's run: its result so far, the running fold counts of that result (quality
  // gate, see transfer_part) and the reports of its parts. The sets of a round run side by side
  // (each from the round's base), so each has its own.
  struct SetRun {
    Eigen::MatrixXd V;
    int si = 0, flips = 0;
    std::vector<PartReport> reports;
    int done = 0, total = 0;  // parts run / in the set (progress)
  };
  int si_current = out.folds_level1.self_intersections_result;
  int flips_current = out.folds_level1.faulty_faces();
  const std::vector<LandmarkPair>& level_pairs = out.level1.landmarks;
  Eigen::MatrixXd lm_ref(level_pairs.size(), 3);
  for (size_t k = 0; k < level_pairs.size(); ++k)
    lm_ref.row(static_cast<Eigen::Index>(k)) = reference.V.row(level_pairs[k].reference);
  auto lm_error = [&](const Eigen::MatrixXd& X) {
    Eigen::MatrixXd lm(level_pairs.size(), 3);
    for (size_t k = 0; k < level_pairs.size(); ++k) lm.row(static_cast<Eigen::Index>(k)) = X.row(level_pairs[k].source);
    return aligned_vertex_error(lm, lm_ref);
  };

  // Transfer I of the part pairs run so far (step 3), by their exact inputs: the sets of a round
  // and the rounds share many parts (two neck windows often cut the same limb, and a part whose
  // region no earlier glue touched sees the same positions again), and the transfer depends only
  // on the two submeshes and the level-1 cage. A hit is the same result bit for bit (lion-07: 11
  // of ~40 part transfers, 9 % of the run). Shared by the sets running side by side.
  struct CachedPartTransfer {
    std::vector<int> sset, rset;
    Eigen::MatrixXd SV;
    PoseTransferResult t;
    bool cage_reused = false;
  };
  std::vector<std::shared_ptr<const CachedPartTransfer>> part_cache;
  std::mutex part_cache_mutex;
  auto cached_transfer = [&](const std::vector<int>& sset, const std::vector<int>& rset, const Eigen::MatrixXd& SV) {
    std::lock_guard<std::mutex> lock(part_cache_mutex);
    for (const auto& c : part_cache)
      if (c->sset == sset && c->rset == rset && c->SV.rows() == SV.rows() && c->SV == SV) return c;
    return std::shared_ptr<const CachedPartTransfer>();
  };
  // One part pair (header, steps 1–5) on the set's current result run.V. Progress: `set_progress`
  // is the set's range, which its parts share in turn.
  auto transfer_part = [&](SetRun& run, const PartPair& pp, int level, const Progress& set_progress) -> Status {
    const auto t0 = clock::now();
    PartReport rep;
    rep.name = pp.name;
    rep.level = level;
    rep.round = round;
    const Progress pp_progress = set_progress.sub(double(run.done) / std::max(1, run.total),
                                                  double(run.done + 1) / std::max(1, run.total));
    ++run.done;
    std::vector<int> sset, rset;
    if (Status s = part_vertices(source.V, source.F, pp.source, &sset); !s.ok())
      return Status::error(s.code, "part \"" + pp.name + "\" (source): " + s.message);
    if (same_conn && part_regions_equal(pp.source, pp.reference)) {
      rset = sset;
    } else if (Status s = part_vertices(reference.V, reference.F, pp.reference, &rset); !s.ok()) {
      return Status::error(s.code, "part \"" + pp.name + "\" (reference): " + s.message);
    }
    PartMesh S = part_submesh(run.V, source.F, sset);
    PartMesh R = part_submesh(reference.V, reference.F, rset);
    rep.source_vertices = static_cast<int>(S.V.rows());
    rep.reference_vertices = static_cast<int>(R.V.rows());
    auto skip = [&](Status s) {
      rep.status = s;
      rep.ms = part_ms_since(t0);
      run.reports.push_back(rep);
      return Status::success();
    };
    if (S.boundary.empty() || R.boundary.empty() || S.tip < 0 || R.tip < 0)
      return skip(Status::error(StatusCode::InvalidMesh, "the part has no cut boundary (it is a closed piece)"));
    // Step 2: butterfly subdivision of both parts by the same number of levels.
    const int n_min = static_cast<int>(std::min(S.V.rows(), R.V.rows()));
    int levels = 0;
    for (long size = n_min; levels < opt.max_subdivisions && size < opt.min_part_vertices; size *= 4) ++levels;
    rep.subdivisions = levels;
    const ButterflyResult Ssub = butterfly_subdivide(S.V, S.F, levels);
    const ButterflyResult Rsub = butterfly_subdivide(R.V, R.F, levels);
    // Step 3: Transfer I on the pair.
    std::vector<LandmarkPair> lm;
    const bool same_pair = S.F.rows() == R.F.rows() && S.F == R.F;
    if (same_pair) R.tip = S.tip;  // one frame construction for both (the distances differ slightly by pose)
    else lm = part_landmarks(R, S, landmarks, nR, nS);
    PoseTransferOptions topt = opt.transfer;
    topt.cage.target_vertices = opt.part_cage_vertices;
    topt.cage.resolution = opt.part_cage_resolution;
    topt.fold_retry_resolution = 0;  // the part gate checks folds itself
    topt.flip_repair_rings = 0;
    topt.placement = TransferPlacement::Reference;
    Mesh Sm{Ssub.V, Ssub.F}, Rm{Rsub.V, Rsub.F};
    // The level-1 cage where it still encloses the part (paper 000 Sec. 5), else its own.
    std::shared_ptr<const CachedPartTransfer> cached = cached_transfer(sset, rset, S.V);
    rep.transfer_reused = cached != nullptr;
    if (!cached) {
      auto c = std::make_shared<CachedPartTransfer>();
      Mesh level_cage;
      if (opt.reuse_level_cage && out.level1.cage_deformed.rows() > 0) {
        level_cage = Mesh{out.level1.cage_deformed, out.level1.cage_faces};
        c->cage_reused = check_user_cage(Sm.V, level_cage.V, &level_cage.F, topt.cage.min_clearance * 1e-3).ok();
        if (c->cage_reused) topt.fixed_cage_weight = opt.reused_cage_fixed_weight;
      }
      c->t = pose_transfer(Rm, Sm, lm, topt, pp_progress.sub(0.0, 0.8), c->cage_reused ? &level_cage : nullptr);
      if (c->t.status.code == StatusCode::Cancelled) return c->t.status;
      c->sset = sset, c->rset = rset, c->SV = S.V;
      cached = c;
      std::lock_guard<std::mutex> lock(part_cache_mutex);
      part_cache.push_back(cached);
    }
    rep.cage_reused = cached->cage_reused;
    const PoseTransferResult& t = cached->t;
    rep.fixed_cage_vertices = t.fixed_cage_vertices;  // (a cancelled transfer returned above, never cached)
    rep.landmarks = static_cast<int>(t.landmarks.size());
    if (!rep.transfer_reused) rep.transfer_ms = t.ms;
    if (!t.status.ok()) return skip(t.status);
    const auto t_glue = clock::now();
    Eigen::MatrixXd T;
    Eigen::MatrixXi Fc;
    butterfly_coarsen(t.V, Ssub.F, levels, static_cast<int>(S.V.rows()), &T, &Fc);
    rep.transfer_flips = transfer_metrics(T, S.V, S.F).faulty_faces();
    // Step 4: registration, rotation about the boundary centroid, then the boundary centroid onto
    // the level-1 one. By the paper's local frames; or rigidly (the level-1 shape turned onto the
    // part's landmarks) when the transfer folded faces.
    rep.rigid = opt.rigid_when_folded && rep.transfer_flips > 0;
    const Eigen::MatrixXd& X = rep.rigid ? S.V : T;  // rigid: the level-1 shape
    Eigen::Matrix3d Rot;
    if (!rep.rigid) {
      bool axis_t = false, axis_r = false;
      const Eigen::Matrix3d Et = part_frame(X, S.boundary, S.tip, &axis_t);
      const Eigen::Matrix3d Er = part_frame(R.V, R.boundary, R.tip, &axis_r);
      if (axis_t || axis_r) Rot = Eigen::Quaterniond::FromTwoVectors(Et.col(0), Er.col(0)).toRotationMatrix();
      else Rot = Er * Et.transpose();
    } else {
      // The rotation that best maps the part's landmark pairs (every vertex when the part pair
      // has one connectivity), each taken from its part's cut centre (Umeyama, with scale: the
      // meshes differ in size).
      Eigen::MatrixXd P, Q;
      if (same_pair) {
        P = S.V, Q = R.V;
      } else {
        P.resize(static_cast<Eigen::Index>(lm.size()), 3), Q.resize(static_cast<Eigen::Index>(lm.size()), 3);
        for (size_t k = 0; k < lm.size(); ++k) {
          P.row(static_cast<Eigen::Index>(k)) = S.V.row(lm[k].source);
          Q.row(static_cast<Eigen::Index>(k)) = R.V.row(lm[k].reference);
        }
      }
      P.rowwise() -= part_boundary_centroid(S.V, S.boundary).transpose();
      Q.rowwise() -= part_boundary_centroid(R.V, R.boundary).transpose();
      RigidFitOptions ro;
      ro.scale = true;
      ro.rotation_prior = 0.01;  // landmarks along a limb say little about the turn about it: none then
      const RigidFit fit = fit_rigid(P, Q, ro);
      if (fit.degenerate)
        return skip(Status::error(StatusCode::InvalidArgument, "its transfer folded " + std::to_string(rep.transfer_flips) +
                                                                  " faces, and its landmarks are too few to turn it rigidly"));
      Rot = fit.R;
    }
    rep.rotation_degrees = Eigen::AngleAxisd(Rot).angle() * 180.0 / M_PI;
    // Transfer I already gives the part the reference part's orientation (the low frequencies
    // carry it), so a large frame rotation means an ill-conditioned frame (a short or straight
    // part whose average point lies near the axis): measured up to 167° on cat-07/cat-05 parts,
    // all rejected by the gate below. Such rotations are not applied: the rotation is tapered
    // from full at max_registration_degrees − 15° to none at + 15° (a hard cut made the result
    // jump with the last bits of the estimate: cat-01's second part measured 46.1° natively and
    // 43.0° in wasm, one side of the cut each). The landmarks' rotation is well conditioned.
    const double taper_lo = opt.max_registration_degrees - 15, taper_hi = opt.max_registration_degrees + 15;
    const double keep = std::clamp((taper_hi - rep.rotation_degrees) / (taper_hi - taper_lo), 0.0, 1.0);
    if (keep < 1 && !rep.rigid) {
      const Eigen::AngleAxisd aa(Rot);
      Rot = Eigen::AngleAxisd(keep * aa.angle(), aa.axis()).toRotationMatrix();
    }
    const Eigen::Vector3d bt = part_boundary_centroid(X, S.boundary);
    const Eigen::Vector3d bs = part_boundary_centroid(S.V, S.boundary);
    Eigen::MatrixXd Treg(X.rows(), 3);
    for (int i = 0; i < X.rows(); ++i) Treg.row(i) = (Rot * (X.row(i).transpose() - bt) + bs).transpose();
    // Step 5: gluing. Free: `seam_rings` rings around the cut on both sides; handle: the
    // part's other vertices at their registered positions; the rest of the mesh stays.
    std::vector<char> in_part(nS, 0);
    for (int v : sset) in_part[v] = 1;
    std::vector<int> cut;
    for (int b : S.boundary) cut.push_back(S.from[b]);
    std::vector<int> band;
    std::vector<int> handle;
    for (int rings = opt.seam_rings; rings >= 1; --rings) {
      band = k_ring(adj_full, cut, rings);
      std::vector<char> in_band(nS, 0);
      for (int v : band) in_band[v] = 1;
      handle.clear();
      for (int i = 0; i < static_cast<int>(S.from.size()); ++i)
        if (!in_band[S.from[i]] || non_manifold[S.from[i]]) handle.push_back(S.from[i]);
      if (!handle.empty()) break;
    }
    if (handle.empty()) return skip(Status::error(StatusCode::InvalidMesh, "the part is too small for its seam band"));
    std::sort(handle.begin(), handle.end());
    EditRegion region;
    region.handles = {handle};
    std::vector<char> in_handle(nS, 0);
    for (int v : handle) in_handle[v] = 1;
    for (int v : band)  // a non-manifold vertex on the body side stays where it is
      if (!in_handle[v] && !non_manifold[v]) region.roi.push_back(v);
    for (int v : sset)  // part vertices outside the submesh (no full face) move with the seam
      if (!in_handle[v] && !non_manifold[v]) region.roi.push_back(v);
    std::sort(region.roi.begin(), region.roi.end());
    region.roi.erase(std::unique(region.roi.begin(), region.roi.end()), region.roi.end());
    rep.seam_vertices = static_cast<int>(region.roi.size());
    for (int v : handle) region.roi.push_back(v);
    std::sort(region.roi.begin(), region.roi.end());
    double l1_mean = 0, l1_max = 0;
    part_seam_dihedral(run.V, source.V, source.F, in_part, &l1_mean, &l1_max);
    LaplacianEditOptions eo;
    eo.handle_basis = false;
    LaplacianEditor editor;
    if (Status s = editor.precompute(run.V, source.F, region, eo, pp_progress.sub(0.8, 0.95)); !s.ok()) {
      if (s.code == StatusCode::Cancelled) return s;
      return skip(Status::error(s.code, "gluing: " + s.message));
    }
    Eigen::MatrixXd targets = run.V;
    for (int i = 0; i < static_cast<int>(S.from.size()); ++i) targets.row(S.from[i]) = Treg.row(i);
    EditResult d = editor.drag_positions(targets);
    if (!d.status.ok()) return skip(Status::error(d.status.code, "gluing: " + d.status.message));
    EditResult fin = editor.finalize(FeatureSize::Keep);
    if (!fin.status.ok()) return skip(Status::error(fin.status.code, "gluing: " + fin.status.message));
    if (!fin.V.allFinite()) return skip(Status::error(StatusCode::NumericalError, "gluing produced non-finite positions"));
    // Quality gate: keep the part only if it brings the level's landmark pairs closer to the
    // reference (after a similarity fit), adds no self-intersection and no flipped or collapsed face, and
    // leaves no seam.
    // "flips" here: flipped or collapsed faces (metrics/transfer_metrics.h).
    int flips_after = transfer_metrics(fin.V, source.V, source.F).faulty_faces();
    if (flips_after > run.flips && opt.transfer.flip_repair_rings > 0) {
      // The glued part folds faces (at its seam, usually): the flip repair first, then the gate.
      FlipRepairOptions fo;
      fo.rings = opt.transfer.flip_repair_rings;
      FlipRepairResult fr = repair_flips(source, fin.V, fo);
      if (fr.status.ok() && fr.faulty_after() < flips_after) {
        rep.flips_repaired = flips_after - fr.faulty_after();
        flips_after = fr.faulty_after();
        fin.V = std::move(fr.V);
      }
    }
    const int si_after = self_intersections(fin.V, source.F).pairs;
    rep.landmark_error_before = lm_error(run.V);
    rep.landmark_error_after = lm_error(fin.V);
    rep.self_intersections_added = si_after - run.si;
    rep.flips_added = flips_after - run.flips;
    part_seam_dihedral(fin.V, source.V, source.F, in_part, &rep.seam_dihedral_mean, &rep.seam_dihedral_max);
    rep.seam_dihedral_mean_before = l1_mean;
    rep.seam_dihedral_max_before = l1_max;
    if (opt.reject_worse_parts) {
      std::string why;
      // Issue 16's bound: no more self-intersecting pairs than the reference and the source
      // together (the Sumner poses themselves have 40–1565: limbs pressed against the body).
      const int si_bound = std::max(run.si, out.folds_level1.self_intersections_reference +
                                                    out.folds_level1.self_intersections_source);
      if (si_after > si_bound)
        why += ", adds " + std::to_string(si_after - run.si) + " self-intersecting pairs (bound " +
               std::to_string(si_bound) + ")";
      if (flips_after > run.flips) why += ", adds " + std::to_string(flips_after - run.flips) + " flipped or collapsed faces";
      if (rep.landmark_error_after > rep.landmark_error_before) why += ", moves the landmarks away from the reference";
      if (rep.seam_dihedral_mean > opt.max_seam_dihedral_mean)
        why += ", leaves a seam (mean dihedral change " + std::to_string(static_cast<int>(std::lround(rep.seam_dihedral_mean))) +
               "° across the cut)";
      if (!why.empty()) {
        rep.rejected = true;
        return skip(Status::error(StatusCode::NotConverged, "rejected: the glued part" + why.substr(1)));
      }
    }
    run.si = si_after;
    run.flips = flips_after;
    run.V = fin.V;
    rep.glue_ms = part_ms_since(t_glue);
    rep.ms = part_ms_since(t0);
    run.reports.push_back(rep);
    return Status::success();
  };
  std::function<Status(SetRun&, const std::vector<PartPair>&, int, const Progress&)> run_level =
      [&](SetRun& run, const std::vector<PartPair>& list, int level, const Progress& set_progress) -> Status {
    for (const PartPair& pp : list) {
      if (Status s = transfer_part(run, pp, level, set_progress); !s.ok()) return s;
      if (!pp.children.empty())
        if (Status s = run_level(run, pp.children, level + 1, set_progress); !s.ok()) return s;
    }
    return Status::success();
  };
  // The sets of a round run side by side (common/threads.h: on the calling thread and the pool;
  // one after another with one thread). Each computes exactly what it would alone, so the result
  // does not depend on the thread count. Only the calling thread reports to `progress`; a set on
  // a pool thread only watches its cancel flag, which the calling thread's reports raise (it polls
  // while it waits).
  const std::thread::id caller = std::this_thread::get_id();
  double shown = 0.45;  // the furthest point the calling thread reported (polled while it waits)
  auto set_sink = [&](double begin, double end) {
    const Progress range = progress.sub(begin, end);
    return Progress([range, &progress, &shown, caller, begin, end](const std::string& stage, double f) {
      if (std::this_thread::get_id() != caller) return !progress.cancelled();
      shown = std::max(shown, begin + f * (end - begin));
      return range.update(stage, f);
    });
  };
  // Each candidate from the round's base (level 1 in the first round); the one whose level
  // landmark pairs end closest to the reference is kept. Within `proposal_tie` (relative) of the
  // best so far counts as a tie, which the earlier candidate (or round) wins: near-equal sets are
  // told apart by the last bits of the part transfers, which differ between builds
  // (docs/transfer.md). Every kept part passed the gate, so no round moves the landmarks away.
  out.landmark_error_level1 = lm_error(out.V_level1);
  out.V = out.V_level1;
  out.landmark_error = out.landmark_error_level1;
  double best = std::numeric_limits<double>::infinity();
  for (; round <= rounds; ++round) {
    if (round > 1) candidates = propose_sets(out.V, nullptr);
    const size_t n_sets = candidates.size();
    // Progress: round r's sets fill [0.45, 1] × (r − 1 + (set + part / parts) / sets) / rounds.
    const double span = 0.55 / rounds;
    auto set_begin = [&](size_t c) { return 0.45 + span * (round - 1 + double(c) / std::max<size_t>(1, n_sets)); };
    std::vector<SetRun> runs(n_sets);
    std::vector<Status> statuses(n_sets);
    for (size_t c = 0; c < n_sets; ++c) {
      runs[c].V = out.V;
      runs[c].si = si_current, runs[c].flips = flips_current;
      runs[c].total = count_parts(candidates[c].parts);
    }
    auto run_set = [&](size_t c) {
      statuses[c] = run_level(runs[c], candidates[c].parts, 2, set_sink(set_begin(c), set_begin(c + 1)));
    };
    {
      std::vector<Task> others;
      for (size_t c = 1; c < n_sets; ++c) others.emplace_back([&run_set, c] { run_set(c); });
      if (n_sets > 0) run_set(0);
      for (Task& t : others)
        while (!t.wait_for(std::chrono::milliseconds(50))) progress.update("parts", shown);
    }
    for (const Status& st : statuses)
      if (!st.ok()) {
        out.status = st;  // the first set's error, or a cancel
        return out;
      }
    int kept = -1;
    for (size_t c = 0; c < n_sets; ++c) {
      const double e = lm_error(runs[c].V);
      // The first set of the first round always stands (a NaN error included).
      if ((round == 1 && c == 0) || e < best * (1 - opt.proposal_tie)) {
        best = e;
        kept = static_cast<int>(c);
      }
    }
    out.proposals_tried += spec ? 0 : static_cast<int>(n_sets);
    if (kept < 0) break;  // no set of this round lands closer: the rounds are over
    SetRun& k = runs[static_cast<size_t>(kept)];
    out.V = std::move(k.V);
    out.landmark_error = best;
    for (PartReport& r : k.reports) out.reports.push_back(std::move(r));
    for (const PartPair& p : candidates[kept].parts) out.parts.parts.push_back(p);
    if (round == 1) out.proposal_kept = kept;
    out.proposal_rounds = round;
    si_current = k.si, flips_current = k.flips;
  }
  out.ms_parts = part_ms_since(t_parts);
  out.folds = fold_report(out.folds_level1, source, out.V);  // the inputs' counts from level 1
  out.ms_total = part_ms_since(t_start);
  progress.update("done", 1.0);
  return out;
}

}  // namespace

PartTransferResult part_transfer(const Mesh& reference, const Mesh& source, const std::vector<LandmarkPair>& landmarks,
                                 const PartsSpec* spec, const PartTransferOptions& opt, const Progress& progress) {
  const auto t_start = std::chrono::steady_clock::now();
  // No folds (PoseTransferOptions::fold_retry_resolution), decided on the final result: the
  // level-1 cage on the finer grid only when the parts on the usual one end with folds. The
  // parts often repair level 1's (cat-07's one flipped face; horse0 → camel_ref's feet), and on
  // the finer, tighter cage fewer parts fit inside the reused level-1 cage.
  const int finer = opt.transfer.fold_retry_resolution;
  const bool may_retry = finer > opt.transfer.cage.resolution;
  PartTransferOptions first = opt;
  first.transfer.fold_retry_resolution = 0;
  // The first pass's progress: level 1 in 0..0.4; its parts end at 1, or at 0.7 when level 1
  // folds (a second pass may follow in 0.7..1).
  std::atomic<bool> second_pass_likely{false};
  const Progress first_progress([&progress, &second_pass_likely](const std::string& stage, double f) {
    const double g = f <= 0.4 ? f : 0.4 + (f - 0.4) * (second_pass_likely.load() ? 0.5 : 1.0);
    return progress.update(stage, g);
  });
  // No flips (PoseTransferOptions::flip_repair_rings) on the result returned.
  const auto finish = [&](PartTransferResult&& r) {
    if (r.status.ok())
      r.status = repair_transfer_flips(source, opt.transfer.flip_repair_rings, progress.sub(0.99, 1.0), &r.V, &r.folds,
                                       &r.flip_repair);
    r.ms_total = part_ms_since(t_start);
    progress.update("done", 1.0);
    return std::move(r);
  };
  PartTransferResult out =
      level_and_parts(reference, source, landmarks, spec, first, first_progress, may_retry ? &second_pass_likely : nullptr);
  if (!out.status.ok() || !may_retry || out.folds.violations() == 0) return finish(std::move(out));
  if (!progress.update("level 1 again with a cage on a finer grid (the result folds)", 0.7)) {
    out.status = cancelled_status("level 1 on a finer grid");
    return out;
  }
  const auto t_retry = std::chrono::steady_clock::now();
  PartTransferOptions second = first;
  second.transfer.cage.resolution = finer;
  // The parts of the second pass run only when its level 1 folds less than the first pass's
  // (michael9 → michael3: 128 flipped faces on either grid, ~25 s of parts saved).
  bool stopped = false;
  PartTransferResult alt = level_and_parts(reference, source, landmarks, spec, second, progress.sub(0.7, 1.0), nullptr,
                                           out.folds_level1.violations(), &stopped);
  if (alt.status.code == StatusCode::Cancelled) return alt;
  FoldRetry retry;
  retry.checked = true;
  retry.tried = true;
  retry.resolution = finer;
  retry.first = out.folds;
  retry.kept = alt.status.ok() && !stopped && alt.folds.violations() < out.folds.violations();
  retry.ms = part_ms_since(t_retry);
  if (retry.kept) out = std::move(alt);
  out.fold_retry = retry;
  return finish(std::move(out));
}

}  // namespace mm
