#include "cage/hull_decimation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <vector>

#include "cage/cage_detail.h"
#include "spatial/quadric.h"
#include "spatial/uniform_grid.h"

namespace mm {

namespace hull_detail {

using cage_detail::Vec3;
using cage_detail::cross;
using cage_detail::dot;
using cage_detail::norm;

constexpr double kPi = 3.14159265358979323846;

struct HeapEntry {
  double cost;
  int a, b;         // a < b
  unsigned va, vb;  // versions of a and b when pushed (lazy deletion: stale when either changed)
  // Priority: lower cost first, ties by vertex indices (deterministic).
  bool before(const HeapEntry& o) const {
    if (cost != o.cost) return cost < o.cost;
    if (a != o.a) return a < o.a;
    return b < o.b;
  }
};

// 4-ary min-heap of 24-byte entries. Edge collapses leave many stale entries behind (lazy
// deletion: an entry is skipped when popped if a vertex it names died or changed since, which
// the version stamps tell without recomputing the cost); four children per node halve the depth
// of a binary heap and share cache lines.
class EdgeHeap {
 public:
  bool empty() const { return h_.empty(); }
  void push(const HeapEntry& e) {
    size_t i = h_.size();
    h_.push_back(e);
    while (i > 0) {
      const size_t parent = (i - 1) / 4;
      if (!h_[i].before(h_[parent])) break;
      std::swap(h_[i], h_[parent]);
      i = parent;
    }
  }
  size_t size() const { return h_.size(); }
  // Drops the entries `stale` names and restores the heap order bottom-up (O(size)); pops of the
  // kept entries come out in the same order as before (the order is total on (cost, a, b)).
  template <class Stale>
  void compact(Stale stale) {
    h_.erase(std::remove_if(h_.begin(), h_.end(), stale), h_.end());
    const size_t n = h_.size();
    if (n < 2) return;
    for (size_t i = (n - 2) / 4 + 1; i-- > 0;) sift_down(i);
  }
  HeapEntry pop() {
    const HeapEntry top = h_[0];
    h_[0] = h_.back();
    h_.pop_back();
    sift_down(0);
    return top;
  }

 private:
  void sift_down(size_t i) {
    const size_t n = h_.size();
    for (;;) {
      const size_t first = 4 * i + 1;
      if (first >= n) break;
      size_t best = first;
      const size_t last = std::min(first + 4, n);
      for (size_t c = first + 1; c < last; ++c)
        if (h_[c].before(h_[best])) best = c;
      if (!h_[best].before(h_[i])) break;
      std::swap(h_[i], h_[best]);
      i = best;
    }
  }

  std::vector<HeapEntry> h_;
};

struct Candidates {
  int n = 0;
  Vec3 p[4];
  double cost[4];
};

// Signed solid angle of triangle (a, b, c) seen from x (Van Oosterom & Strackee 1983);
// positive when x is on the inner side of a counter-clockwise (outward) triangle.
double hull_solid_angle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 A = a - x, B = b - x, C = c - x;
  const double la = norm(A), lb = norm(B), lc = norm(C);
  const double det = dot(A, cross(B, C));
  const double den = la * lb * lc + dot(A, B) * lc + dot(A, C) * lb + dot(B, C) * la;
  return 2.0 * std::atan2(det, den);
}

class Decimator {
 public:
  Decimator(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXd& P, double clearance,
            const HullDecimationOptions& opt)
      : opt_(opt), point_pos_(P), points_(P), clearance_(clearance) {
    const int n = static_cast<int>(V.rows());
    pos_.resize(n);
    for (int i = 0; i < n; ++i) pos_[i] = Vec3(V(i, 0), V(i, 1), V(i, 2));
    faces_.resize(F.rows());
    face_alive_.assign(F.rows(), 1);
    vf_.resize(n);
    quadric_.resize(n);
    vert_alive_.assign(n, 0);
    version_.assign(n, 0);
    for (int f = 0; f < F.rows(); ++f) {
      faces_[f] = {F(f, 0), F(f, 1), F(f, 2)};
      for (int c = 0; c < 3; ++c) {
        vf_[F(f, c)].push_back(f);
        vert_alive_[F(f, c)] = 1;
      }
      const Vec3 A = face_area_vector(f);
      const double a2 = norm(A);
      if (a2 > 0) {
        const Vec3 nrm = (1.0 / a2) * A;
        const double d = dot(nrm, pos_[faces_[f][0]]);
        for (int c = 0; c < 3; ++c) quadric_[F(f, c)].add_plane(nrm.x, nrm.y, nrm.z, d, 0.5 * a2);
      }
    }
    alive_vertices_ = 0;
    for (int i = 0; i < n; ++i) alive_vertices_ += vert_alive_[i];
    alive_faces_ = static_cast<int>(F.rows());
    face_range_.resize(F.rows());
    in_grid_.assign(F.rows(), 0);
    cos_turn_ = std::cos(opt_.max_normal_turn_deg * kPi / 180.0);
  }

  Status run(const Progress& progress, int* collapses) {
    rebuild_grid();
    for (int a = 0; a < static_cast<int>(pos_.size()); ++a) {
      if (!vert_alive_[a]) continue;
      neighbours(a, &scratch_[0]);
      for (int b : scratch_[0])
        if (a < b) push(a, b);
    }
    const int start = alive_vertices_;
    int done = 0;
    while (alive_vertices_ > opt_.target_vertices && !heap_.empty()) {
      // Every collapse leaves the entries of the edges around both ends stale (~10): once they
      // outnumber the live edges (≤ 3 per vertex on a closed surface plus a margin), drop them,
      // so that pops stop paying for stale entries in a heap several times too deep. (At least
      // twice the size the last compaction left: linear time overall whatever the surface.)
      if (heap_.size() > std::max(6 * static_cast<size_t>(alive_vertices_) + 64, 2 * compacted_size_)) {
        heap_.compact([&](const HeapEntry& h) {
          return !vert_alive_[h.a] || !vert_alive_[h.b] || h.va != version_[h.a] || h.vb != version_[h.b];
        });
        compacted_size_ = heap_.size();
      }
      const HeapEntry e = heap_.pop();
      if (!vert_alive_[e.a] || !vert_alive_[e.b]) continue;
      // The cost depends only on the state of a and b; when either changed, a fresh entry was
      // pushed with the new versions and this one is stale.
      if (e.va != version_[e.a] || e.vb != version_[e.b]) continue;
      const Candidates c = candidates(e.a, e.b);
      if (c.n == 0) continue;
      if (!collapse(e.a, e.b, c)) continue;
      ++done;
      if (alive_faces_ * 2 < grid_faces_) rebuild_grid();
      if (done % 256 == 0) {
        const double f = double(start - alive_vertices_) / std::max(1, start - opt_.target_vertices);
        if (!progress.update("cage: simplify", f)) return cancelled_status("cage: simplify");
      }
    }
    *collapses = done;
    return Status::success();
  }

  void output(Eigen::MatrixXd* V, Eigen::MatrixXi* F) const {
    std::vector<int> remap(pos_.size(), -1);
    int n = 0;
    for (size_t i = 0; i < pos_.size(); ++i)
      if (vert_alive_[i]) remap[i] = n++;
    V->resize(n, 3);
    for (size_t i = 0; i < pos_.size(); ++i)
      if (remap[i] >= 0) {
        (*V)(remap[i], 0) = pos_[i].x;
        (*V)(remap[i], 1) = pos_[i].y;
        (*V)(remap[i], 2) = pos_[i].z;
      }
    F->resize(alive_faces_, 3);
    int m = 0;
    for (size_t f = 0; f < faces_.size(); ++f)
      if (face_alive_[f]) {
        for (int c = 0; c < 3; ++c) (*F)(m, c) = remap[faces_[f][c]];
        ++m;
      }
  }

 private:
  Vec3 face_area_vector(int f) const {
    return cage_detail::area_vector(pos_[faces_[f][0]], pos_[faces_[f][1]], pos_[faces_[f][2]]);
  }

  // Alive incident faces of v (also drops dead ones from the list).
  const std::vector<int>& faces_of(int v) {
    auto& list = vf_[v];
    list.erase(std::remove_if(list.begin(), list.end(), [&](int f) { return !face_alive_[f]; }), list.end());
    return list;
  }

  // The neighbours of v, ascending, into *out (a reused buffer: this runs several times per
  // collapse, and allocating was a tenth of the decimation's time).
  void neighbours(int v, std::vector<int>* out) {
    out->clear();
    for (int f : faces_of(v))
      for (int c = 0; c < 3; ++c)
        if (faces_[f][c] != v) out->push_back(faces_[f][c]);
    std::sort(out->begin(), out->end());
    out->erase(std::unique(out->begin(), out->end()), out->end());
  }

  static bool has_vertex(const std::array<int, 3>& t, int v) { return t[0] == v || t[1] == v || t[2] == v; }

  // Faces around a or b, each once (edge faces included), into *s.
  void star(int a, int b, std::vector<int>* s) {
    *s = faces_of(a);
    for (int f : faces_of(b))
      if (!has_vertex(faces_[f], a)) s->push_back(f);
  }

  // Up to four positions for the merged vertex (quadric minimiser, midpoint, endpoints),
  // sorted by cost = quadric error / area (mean squared distance to the offset surface's
  // planes) + length_weight · |ab|².
  Candidates candidates(int a, int b) const {
    Candidates out;
    Quadric q = quadric_[a];
    q.add(quadric_[b]);
    const Vec3 pa = pos_[a], pb = pos_[b], mid = 0.5 * (pa + pb);
    const double len2 = dot(pb - pa, pb - pa);
    const double len = std::sqrt(len2);
    Vec3 cand[4];
    int nc = 0;
    double m[3];
    if (q.minimiser(m)) {
      const Vec3 opt_p(m[0], m[1], m[2]);
      if (norm(opt_p - mid) < len) cand[nc++] = opt_p;
    }
    cand[nc++] = mid;
    cand[nc++] = pa;
    cand[nc++] = pb;
    const double norm_area = q.area > 0 ? q.area : 1.0;
    for (int i = 0; i < nc; ++i) {
      out.p[i] = cand[i];
      out.cost[i] = std::max(0.0, q.eval(cand[i].x, cand[i].y, cand[i].z)) / norm_area + opt_.length_weight * len2;
    }
    out.n = nc;
    // Insertion sort, stable (deterministic order for equal costs).
    for (int i = 1; i < nc; ++i)
      for (int j = i; j > 0 && out.cost[j] < out.cost[j - 1]; --j) {
        std::swap(out.cost[j], out.cost[j - 1]);
        std::swap(out.p[j], out.p[j - 1]);
      }
    return out;
  }

  void push(int a, int b) {
    const Candidates c = candidates(a, b);
    if (c.n > 0) heap_.push({c.cost[0], a, b, version_[a], version_[b]});
  }

  bool collapse(int a, int b, const Candidates& cands) {
    // Link condition: the common neighbours of a and b are exactly the two opposite vertices.
    int edge_faces[2], n_edge_faces = 0;
    for (int f : faces_of(a))
      if (has_vertex(faces_[f], b) && n_edge_faces++ < 2) edge_faces[n_edge_faces - 1] = f;
    if (n_edge_faces != 2) return false;
    int opposite[2];
    for (int k = 0; k < 2; ++k) {
      const auto& t = faces_[edge_faces[k]];
      opposite[k] = t[0] != a && t[0] != b ? t[0] : (t[1] != a && t[1] != b ? t[1] : t[2]);
    }
    if (opposite[0] == opposite[1]) return false;
    std::vector<int>&na = scratch_[0], &nb = scratch_[1], &other = scratch_[2];
    neighbours(a, &na);
    neighbours(b, &nb);
    size_t common = 0;  // |na ∩ nb| (both ascending)
    for (size_t i = 0, j = 0; i < na.size() && j < nb.size();) {
      if (na[i] < nb[j]) ++i;
      else if (nb[j] < na[i]) ++j;
      else ++common, ++i, ++j;
    }
    if (common != 2) return false;
    if (static_cast<int>(na.size() + nb.size()) - 4 < 3) return false;
    for (int k = 0; k < 2; ++k) {
      neighbours(opposite[k], &other);
      if (other.size() <= 3) return false;
    }

    std::vector<int>& s = scratch_[3];
    star(a, b, &s);
    for (int k = 0; k < cands.n; ++k)
      if (valid_position(a, b, s, cands.p[k])) {
        apply(a, b, edge_faces, cands.p[k]);
        return true;
      }
    return false;
  }

  // Geometry tests of moving a and b to p: no flipped or degenerate face, no self-intersection,
  // no point leaving the surface or coming closer than the clearance.
  bool valid_position(int a, int b, const std::vector<int>& s, const Vec3& p) {
    std::vector<std::array<Vec3, 3>>&moved = moved_, &old = old_;
    std::vector<std::array<int, 3>>& moved_ids = moved_ids_;
    moved.clear();
    old.clear();
    moved_ids.clear();
    Vec3 lo = p, hi = p;
    double largest = 0;
    for (int f : s) largest = std::max(largest, norm(face_area_vector(f)));
    for (int f : s) {
      const auto& t = faces_[f];
      const std::array<Vec3, 3> O = {pos_[t[0]], pos_[t[1]], pos_[t[2]]};
      old.push_back(O);
      for (const Vec3& v : O) {
        lo = Vec3(std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z));
        hi = Vec3(std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z));
      }
      if (has_vertex(t, a) && has_vertex(t, b)) continue;
      std::array<Vec3, 3> P = O;
      std::array<int, 3> ids = t;
      for (int c = 0; c < 3; ++c)
        if (t[c] == a || t[c] == b) {
          P[c] = p;
          ids[c] = a;
        }
      const Vec3 old_n = cage_detail::area_vector(O[0], O[1], O[2]);
      const Vec3 new_n = cage_detail::area_vector(P[0], P[1], P[2]);
      const double lo_n = norm(old_n), ln = norm(new_n);
      if (!(ln > 1e-12 * lo_n) || !(ln > 0)) return false;
      // Slivers (the offset surface has many) have meaningless normals: no turn test for them.
      if (lo_n > 1e-2 * largest && dot(old_n, new_n) < cos_turn_ * lo_n * ln) return false;
      moved.push_back(P);
      moved_ids.push_back(ids);
    }
    if (opt_.check_self_intersections && hits_other_face(moved, moved_ids, a, b)) {
      return false;
    }
    // Points: the winding number changes only inside the region swept between the old and the
    // new star, which lies in the bounding box of their vertices.
    const Vec3 pad(clearance_, clearance_, clearance_);
    const double c2 = clearance_ * clearance_;
    return points_.for_each_in_box(lo - pad, hi + pad, [&](int i) {
      const Vec3 x(point_pos_(i, 0), point_pos_(i, 1), point_pos_(i, 2));
      double delta = 0;
      for (const auto& P : moved) {
        if (clearance_ > 0 && cage_detail::point_triangle_distance2(x, P[0], P[1], P[2]) < c2) return false;
        delta += hull_solid_angle(x, P[0], P[1], P[2]);
      }
      for (const auto& O : old) delta -= hull_solid_angle(x, O[0], O[1], O[2]);
      return std::abs(delta) < 2 * kPi;
    });
  }

  void apply(int a, int b, const int edge_faces[2], const Vec3& p) {
    for (int k = 0; k < 2; ++k) {
      face_alive_[edge_faces[k]] = 0;
      grid_remove(edge_faces[k]);
    }
    alive_faces_ -= 2;
    pos_[a] = p;
    ++version_[a];
    quadric_[a].add(quadric_[b]);
    for (int f : faces_of(b)) {
      for (int c = 0; c < 3; ++c)
        if (faces_[f][c] == b) faces_[f][c] = a;
      vf_[a].push_back(f);
    }
    vf_[b].clear();
    vert_alive_[b] = 0;
    --alive_vertices_;
    auto& list = vf_[a];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    for (int f : faces_of(a)) grid_insert(f);
    std::vector<int>& na = scratch_[0];
    neighbours(a, &na);
    for (int x : na) push(std::min(a, x), std::max(a, x));
  }

  // --- uniform grid over face bounding boxes, rebuilt as faces grow ---
  void rebuild_grid() {
    double edge_sum = 0;
    int edges = 0;
    Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
    for (size_t f = 0; f < faces_.size(); ++f) {
      if (!face_alive_[f]) continue;
      for (int c = 0; c < 3; ++c) {
        const Vec3& P = pos_[faces_[f][c]];
        lo = Vec3(std::min(lo.x, P.x), std::min(lo.y, P.y), std::min(lo.z, P.z));
        hi = Vec3(std::max(hi.x, P.x), std::max(hi.y, P.y), std::max(hi.z, P.z));
        edge_sum += norm(pos_[faces_[f][(c + 1) % 3]] - P);
        ++edges;
      }
    }
    const Vec3 ext = hi - lo;
    double cs = 2.0 * edge_sum / std::max(1, edges);
    const double longest = std::max({ext.x, ext.y, ext.z, 1e-300});
    cs = std::max(cs, longest / 96.0);  // at most ~96 cells along the longest side
    UniformGrid g;
    const Vec3 glo = lo - Vec3(cs, cs, cs);
    g.cell = cs;
    for (int k = 0; k < 3; ++k) {
      g.lo[k] = glo[k];
      g.dims[k] = static_cast<int>(std::ceil((ext[k] + 2 * cs) / cs)) + 1;
    }
    face_grid_.reset(g);
    std::fill(in_grid_.begin(), in_grid_.end(), 0);
    for (size_t f = 0; f < faces_.size(); ++f)
      if (face_alive_[f]) grid_insert(static_cast<int>(f));
    grid_faces_ = alive_faces_;
  }

  static void bbox(const std::array<Vec3, 3>& P, Vec3* lo, Vec3* hi) {
    *lo = Vec3(std::min({P[0].x, P[1].x, P[2].x}), std::min({P[0].y, P[1].y, P[2].y}),
               std::min({P[0].z, P[1].z, P[2].z}));
    *hi = Vec3(std::max({P[0].x, P[1].x, P[2].x}), std::max({P[0].y, P[1].y, P[2].y}),
               std::max({P[0].z, P[1].z, P[2].z}));
  }

  std::array<Vec3, 3> face_points(int f) const {
    return {pos_[faces_[f][0]], pos_[faces_[f][1]], pos_[faces_[f][2]]};
  }

  // Float box that contains the double box [lo, hi] (rounded outward).
  static void float_box(const Vec3& lo, const Vec3& hi, float flo[3], float fhi[3]) {
    for (int k = 0; k < 3; ++k) {
      flo[k] = static_cast<float>(lo[k]);
      if (static_cast<double>(flo[k]) > lo[k]) flo[k] = std::nextafter(flo[k], -HUGE_VALF);
      fhi[k] = static_cast<float>(hi[k]);
      if (static_cast<double>(fhi[k]) < hi[k]) fhi[k] = std::nextafter(fhi[k], HUGE_VALF);
    }
  }

  // Files face f under its current box (first dropping its earlier copies); a face that moved
  // is filed again, a face that died only dropped, so the grid holds every alive face once.
  void grid_insert(int f) {
    grid_remove(f);
    if (!face_alive_[f]) return;
    Vec3 lo, hi;
    bbox(face_points(f), &lo, &hi);
    CellEntry e;
    e.f = f;
    float_box(lo, hi, e.lo, e.hi);
    face_range_[f] = face_grid_.range(lo, hi);
    face_grid_.insert(face_range_[f], e);
    in_grid_[f] = 1;
  }
  void grid_remove(int f) {
    if (!in_grid_[f]) return;
    face_grid_.remove(face_range_[f], [f](const CellEntry& c) { return c.f == f; });
    in_grid_[f] = 0;
  }

  // True when one of the moved faces crosses a face that shares no vertex with it. One grid
  // query over the bounding box of all moved faces collects the candidates.
  bool hits_other_face(const std::vector<std::array<Vec3, 3>>& moved, const std::vector<std::array<int, 3>>& ids,
                       int a, int b) {
    if (moved.empty()) return false;
    std::vector<Vec3>&mlo = mlo_, &mhi = mhi_;
    mlo.resize(moved.size());
    mhi.resize(moved.size());
    Vec3 lo, hi;
    for (size_t k = 0; k < moved.size(); ++k) {
      bbox(moved[k], &mlo[k], &mhi[k]);
      lo = k == 0 ? mlo[k] : Vec3(std::min(lo.x, mlo[k].x), std::min(lo.y, mlo[k].y), std::min(lo.z, mlo[k].z));
      hi = k == 0 ? mhi[k] : Vec3(std::max(hi.x, mhi[k].x), std::max(hi.y, mhi[k].y), std::max(hi.z, mhi[k].z));
    }
    // The entry's stored box (rounded outward) rejects most candidates without touching the
    // face arrays (the grid holds each alive face once, under its current box).
    const bool clear = face_grid_.for_each_in_box(lo, hi, [&](const CellEntry& ce) {
      if (ce.lo[0] > hi.x || ce.lo[1] > hi.y || ce.lo[2] > hi.z || ce.hi[0] < lo.x || ce.hi[1] < lo.y ||
          ce.hi[2] < lo.z)
        return true;
      const int g = ce.f;
      const auto& t = faces_[g];
      if (has_vertex(t, a) || has_vertex(t, b)) return true;  // part of the star
      const auto Q = face_points(g);
      Vec3 qlo, qhi;
      bbox(Q, &qlo, &qhi);
      if (qlo.x > hi.x || qlo.y > hi.y || qlo.z > hi.z || qhi.x < lo.x || qhi.y < lo.y || qhi.z < lo.z)
        return true;
      for (size_t k = 0; k < moved.size(); ++k) {
        if (qlo.x > mhi[k].x || qlo.y > mhi[k].y || qlo.z > mhi[k].z || qhi.x < mlo[k].x ||
            qhi.y < mlo[k].y || qhi.z < mlo[k].z)
          continue;
        if (has_vertex(t, ids[k][0]) || has_vertex(t, ids[k][1]) || has_vertex(t, ids[k][2])) continue;
        const auto& P = moved[k];
        if (cage_detail::triangles_intersect(P[0], P[1], P[2], Q[0], Q[1], Q[2])) return false;  // hit
      }
      return true;
    });
    return !clear;
  }

  HullDecimationOptions opt_;
  // Buffers reused across collapses (contents meaningful only inside one call).
  std::vector<int> scratch_[4];
  std::vector<std::array<Vec3, 3>> moved_, old_;
  std::vector<std::array<int, 3>> moved_ids_;
  std::vector<Vec3> mlo_, mhi_;
  const Eigen::MatrixXd& point_pos_;  // the points to keep inside (rows)
  PointGrid points_;
  double clearance_ = 0;
  double cos_turn_ = 0;
  std::vector<Vec3> pos_;
  std::vector<std::array<int, 3>> faces_;
  std::vector<uint8_t> face_alive_;
  std::vector<std::vector<int>> vf_;
  std::vector<Quadric> quadric_;
  std::vector<uint8_t> vert_alive_;
  std::vector<unsigned> version_;  // bumped whenever a vertex moves (heap lazy deletion)
  EdgeHeap heap_;
  size_t compacted_size_ = 0;  // heap size after the last compaction
  int alive_vertices_ = 0, alive_faces_ = 0, grid_faces_ = 0;
  struct CellEntry {
    int f;
    float lo[3], hi[3];  // bounding box of the face then, rounded outward
  };
  BoxGrid<CellEntry> face_grid_;  // faces by bounding box, rebuilt as faces grow
  std::vector<BoxGrid<CellEntry>::Range> face_range_;  // per face: the cells holding it (when in_grid_)
  std::vector<uint8_t> in_grid_;
};

}  // namespace hull_detail

HullDecimation hull_decimation(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXd& P,
                               double clearance, const HullDecimationOptions& opt, const Progress& progress) {
  HullDecimation out;
  if (opt.target_vertices < 4) {
    out.status = Status::error(StatusCode::InvalidArgument, "hull decimation needs a target of at least 4 vertices");
    return out;
  }
  if (V.rows() < 4 || F.rows() < 4 || !V.allFinite() || !P.allFinite()) {
    out.status = Status::error(StatusCode::InvalidMesh, "hull decimation needs a closed mesh with finite coordinates");
    return out;
  }
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (F(f, c) < 0 || F(f, c) >= V.rows()) {
        out.status = Status::error(StatusCode::InvalidMesh, "face " + std::to_string(f) + " has an invalid vertex index");
        return out;
      }
  hull_detail::Decimator d(V, F, P, clearance, opt);
  out.status = d.run(progress, &out.collapses);
  if (!out.status.ok()) return out;
  d.output(&out.V, &out.F);
  progress.update("cage: simplify", 1.0);
  return out;
}

}  // namespace mm
