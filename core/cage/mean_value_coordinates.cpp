#include "cage/mean_value_coordinates.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__wasm_simd128__)
#include <wasm_simd128.h>
#endif

#include "common/portable_math.h"
#include "common/threads.h"

namespace mm {

namespace {

#if defined(__SSE2__) || defined(__wasm_simd128__)
#define MM_MVC_PAIRS 1
// Two doubles, one per SIMD lane (GCC/Clang vector extension: + − × ÷ and comparisons work
// lane by lane, a scalar operand is broadcast).
typedef double MvcPair __attribute__((vector_size(16)));
typedef decltype(MvcPair{} < MvcPair{}) MvcMask;  // lane masks: all ones or zero
inline MvcPair lane_sqrt(MvcPair x) {
#if defined(__SSE2__)
  return _mm_sqrt_pd(x);
#else
  return (MvcPair)wasm_f64x2_sqrt((v128_t)x);
#endif
}
inline MvcPair lane_select(MvcMask m, MvcPair a, MvcPair b) { return (MvcPair)(((MvcMask)a & m) | ((MvcMask)b & ~m)); }
inline MvcPair lane_min1(MvcPair v) { return lane_select(v < 1.0, v, MvcPair{1.0, 1.0}); }   // std::min(1.0, v)
inline MvcPair lane_max0(MvcPair v) { return lane_select(0.0 < v, v, MvcPair{0.0, 0.0}); }   // std::max(0.0, v)
inline bool any_lane(MvcMask m) { return (m[0] | m[1]) != 0; }
inline MvcMask lanes_at_least_half(MvcPair h) { return h >= 0.5; }
inline double lane(MvcPair v, int k) { return v[k]; }
inline void set_lane(MvcPair* v, int k, double x) { (*v)[k] = x; }
inline int lane_count(MvcPair) { return 2; }
#else
#define MM_MVC_PAIRS 0
#endif
inline double lane_sqrt(double x) { return std::sqrt(x); }
inline double lane_min1(double v) { return std::min(1.0, v); }
inline double lane_max0(double v) { return std::max(0.0, v); }
inline bool any_lane(bool m) { return m; }
inline bool lanes_at_least_half(double h) { return h >= 0.5; }
inline double lane(double v, int) { return v; }
inline void set_lane(double* v, int, double x) { *v = x; }
inline int lane_count(double) { return 1; }

struct MvcCage {
  const Eigen::MatrixXd& C;
  const Eigen::MatrixXi& CF;
  const std::vector<std::array<int, 2>>& edges;
  const std::vector<std::array<int, 3>>& face_edge;
  double vertex_eps;
};

// Per-thread buffers for one point (T = double) or two (T = MvcPair).
template <class T>
struct MvcLanes {
  MvcLanes(int nc, int ne) : ux(nc), uy(nc), uz(nc), d(nc), inv_d(nc), w(nc), half(ne), th(ne), sn(ne), cs(ne), inv_sn(ne) {}
  std::vector<T> ux, uy, uz, d, inv_d, w;  // per cage vertex
  std::vector<T> half, th, sn, cs, inv_sn;  // per cage edge
};

constexpr int kMvcAllFaces = -1;

// The unnormalised mean-value weights of the point(s) (x, y, z) into b->w (JSW 2005 with the
// exact per-face form of the header). Returns the cage vertex a point sits on (T = double), or
// kMvcAllFaces. When a face's plane contains a point (|det| < 1e-10 in some lane),
// in_plane(f) decides: true goes on with the next face, false stops (the caller then owns
// b->w); with T = MvcPair the pair is redone one point at a time, as when a point sits on a
// vertex (returns −2 then).
template <class T, class InPlane>
int mvc_weights(const MvcCage& cg, T x, T y, T z, MvcLanes<T>* b, InPlane in_plane) {
  const int nc = static_cast<int>(cg.C.rows()), ne = static_cast<int>(cg.edges.size());
  const int nf = static_cast<int>(cg.CF.rows());
  for (int j = 0; j < nc; ++j) {
    const T ex = cg.C(j, 0) - x, ey = cg.C(j, 1) - y, ez = cg.C(j, 2) - z;
    const T dj = lane_sqrt(ex * ex + ey * ey + ez * ez);
    if (any_lane(dj < cg.vertex_eps)) return lane_count(dj) == 1 ? j : -2;
    b->d[j] = dj;
    b->inv_d[j] = 1.0 / dj;
    b->ux[j] = ex * b->inv_d[j];
    b->uy[j] = ey * b->inv_d[j];
    b->uz[j] = ez * b->inv_d[j];
  }
  // Per edge: θ = 2 asin(|u_a − u_b| / 2), the angle the edge subtends at the point, with sin θ
  // and cos θ; the gathers first, then a loop over the edges' arrays. θ takes the C library's
  // asin bits in every build: they reach every transfer result, and the automatic transfer
  // amplifies last-bit changes (docs/status.md). wasm's C library is musl, whose asin is
  // fdlibm's; portable_asin has its bits, inline, so there the loop vectorises (asin below 1/2:
  // nearly every edge subtends less than 60°) and the few wider edges come last.
  for (int e = 0; e < ne; ++e) {
    const int a = cg.edges[e][0], c = cg.edges[e][1];
    const T dx = b->ux[a] - b->ux[c], dy = b->uy[a] - b->uy[c], dz = b->uz[a] - b->uz[c];
    b->half[e] = lane_min1(0.5 * lane_sqrt(dx * dx + dy * dy + dz * dz));
  }
  for (int e = 0; e < ne; ++e) {
    const T h = b->half[e];
#if defined(__EMSCRIPTEN__)
    b->th[e] = 2.0 * asin_below_half(h);
#else
    for (int k = 0; k < lane_count(h); ++k) set_lane(&b->th[e], k, 2.0 * std::asin(lane(h, k)));
#endif
    b->sn[e] = 2.0 * h * lane_sqrt(lane_max0(1.0 - h * h));
    b->cs[e] = 1.0 - 2.0 * h * h;
    b->inv_sn[e] = 1.0 / b->sn[e];  // divisions hoisted out of the face loop (most of its time)
  }
#if defined(__EMSCRIPTEN__)
  for (int e = 0; e < ne; ++e)
    if (any_lane(lanes_at_least_half(b->half[e])))
      for (int k = 0; k < lane_count(b->half[e]); ++k)
        if (lane(b->half[e], k) >= 0.5) set_lane(&b->th[e], k, 2.0 * portable_asin(lane(b->half[e], k)));
#endif
  std::fill(b->w.begin(), b->w.end(), T{} * 0.0);
  for (int f = 0; f < nf; ++f) {
    const int i0 = cg.CF(f, 0), i1 = cg.CF(f, 1), i2 = cg.CF(f, 2);
    const int e0 = cg.face_edge[f][0], e1 = cg.face_edge[f][1], e2 = cg.face_edge[f][2];
    const T *ux = b->ux.data(), *uy = b->uy.data(), *uz = b->uz.data();
    const T det = ux[i0] * (uy[i1] * uz[i2] - uz[i1] * uy[i2]) - uy[i0] * (ux[i1] * uz[i2] - uz[i1] * ux[i2]) +
                  uz[i0] * (ux[i1] * uy[i2] - uy[i1] * ux[i2]);
    if (any_lane((det < 1e-10) & (det > -1e-10))) {  // |det| < 1e-10
      if (lane_count(det) > 1) return -2;
      if (!in_plane(f)) return kMvcAllFaces;
      continue;
    }
    const T t0 = b->th[e0], t1 = b->th[e1], t2 = b->th[e2];
    const T s0 = b->sn[e0], s1 = b->sn[e1], s2 = b->sn[e2];
    const T c0 = b->cs[e0], c1 = b->cs[e1], c2 = b->cs[e2];
    const T is0 = b->inv_sn[e0], is1 = b->inv_sn[e1], is2 = b->inv_sn[e2];
    const T C0 = (c0 - c1 * c2) * (is1 * is2);
    const T C1 = (c1 - c2 * c0) * (is2 * is0);
    const T C2 = (c2 - c0 * c1) * (is0 * is1);
    const T inv_det = 1.0 / det;
    b->w[i0] += s0 * (t0 - C1 * t2 - C2 * t1) * (b->inv_d[i0] * inv_det);
    b->w[i1] += s1 * (t1 - C2 * t0 - C0 * t2) * (b->inv_d[i1] * inv_det);
    b->w[i2] += s2 * (t2 - C0 * t1 - C1 * t0) * (b->inv_d[i2] * inv_det);
  }
  return kMvcAllFaces;
}

}  // namespace

MeanValueCoordinates mean_value_coordinates(const Eigen::MatrixXd& P, const Eigen::MatrixXd& C,
                                            const Eigen::MatrixXi& CF, const Progress& progress) {
  MeanValueCoordinates out;
  const int np = static_cast<int>(P.rows());
  const int nc = static_cast<int>(C.rows());
  const int nf = static_cast<int>(CF.rows());
  if (nc < 4 || nf < 4 || !C.allFinite()) {
    out.status = Status::error(StatusCode::InvalidArgument, "mean-value coordinates need a closed cage with finite vertices");
    return out;
  }
  // Unique undirected edges; each face refers to the edge opposite each of its corners.
  std::map<std::pair<int, int>, int> edge_id;  // ordered: edge numbering is deterministic
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 3>> face_edge(nf);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = CF(f, (k + 1) % 3), b = CF(f, (k + 2) % 3);
      if (a < 0 || b < 0 || a >= nc || b >= nc || a == b) {
        out.status = Status::error(StatusCode::InvalidArgument, "cage face " + std::to_string(f) + " is invalid");
        return out;
      }
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = edge_id.find(key);
      if (it == edge_id.end()) {
        it = edge_id.emplace(key, static_cast<int>(edges.size())).first;
        edges.push_back({key.first, key.second});
      }
      face_edge[f][k] = it->second;
    }
  const int ne = static_cast<int>(edges.size());
  const double scale = (C.colwise().maxCoeff() - C.colwise().minCoeff()).norm();
  const double vertex_eps = 1e-12 * scale;
  constexpr double kPi = 3.14159265358979323846;

  // Rows are independent: computed in blocks of points across the task threads
  // (common/threads.h; bit-identical for any split). Only the first block, on the calling thread,
  // reports progress; the others stop when it is cancelled. A failing point stops its block; the
  // error reported is the lowest failing point's, as in one pass.
  out.Psi.resize(np, nc);
  std::atomic<bool> stop{false};
  std::mutex failure_mutex;
  long failed_at = np;
  auto fail = [&](long p, Status status) {
    std::lock_guard<std::mutex> lock(failure_mutex);
    if (p < failed_at) failed_at = p, out.status = std::move(status);
  };
  const MvcCage cage{C, CF, edges, face_edge, vertex_eps};
  parallel_blocks(np, 1024, [&](long begin, long end) {
    // Filled column by column (one point per column, contiguous) into a small block that is
    // copied transposed into the rows of Psi every kBlock points: writing the rows of a
    // column-major #P × #C matrix directly is strided and was most of the time, and a full
    // #C × #P transpose buffer (80 MB for 22k points and 450 cage vertices) cost another ~0.1 s.
    constexpr int kBlock = 32;  // even: a pair of points never straddles two blocks
    Eigen::MatrixXd PsiT(nc, kBlock);
    auto flush = [&](long first, long count) {
      out.Psi.middleRows(first, count) = PsiT.leftCols(count).transpose();
    };
    MvcLanes<double> one(nc, ne);
#if MM_MVC_PAIRS
    MvcLanes<MvcPair> two(nc, ne);
#endif
    // Writes point p's row into PsiT's column col; false (and the failure reported) when its
    // weights cancel.
    auto finish = [&](long p, int col, double sum, auto weight) {
      if (!(std::abs(sum) > 0) || !std::isfinite(sum)) {
        fail(p, Status::error(StatusCode::NumericalError,
                              "mean-value weights of point " + std::to_string(p) + " cancel (is it inside the cage?)"));
        return false;
      }
      const double inv = 1.0 / sum;
      for (int j = 0; j < nc; ++j) PsiT(j, col) = weight(j) * inv;
      return true;
    };
    auto single = [&](long p, int col) {
      const int at_vertex = mvc_weights(cage, P(p, 0), P(p, 1), P(p, 2), &one, [&](int f) {
        // The point lies in face f's plane (det ≈ 0). On the face (spherical excess ~2π): the
        // face's 2D barycentric coordinates (JSW Fig. 4), and the loop stops; outside it: no
        // contribution.
        const int i0 = CF(f, 0), i1 = CF(f, 1), i2 = CF(f, 2);
        const int e0 = face_edge[f][0], e1 = face_edge[f][1], e2 = face_edge[f][2];
        const double h = 0.5 * (one.th[e0] + one.th[e1] + one.th[e2]);
        if (!(kPi - h < 1e-7)) return true;
        std::fill(one.w.begin(), one.w.end(), 0.0);
        one.w[i0] = one.sn[e0] * one.d[i2] * one.d[i1];
        one.w[i1] = one.sn[e1] * one.d[i0] * one.d[i2];
        one.w[i2] = one.sn[e2] * one.d[i1] * one.d[i0];
        return false;
      });
      if (at_vertex >= 0) {
        PsiT.col(col).setZero();
        PsiT(at_vertex, col) = 1.0;
        return true;
      }
      double sum = 0;
      for (int j = 0; j < nc; ++j) sum += one.w[j];
      return finish(p, col, sum, [&](int j) { return one.w[j]; });
    };
    for (long p = begin; p < end;) {
      const long local = p - begin;
      if (local > 0 && local % kBlock == 0) flush(p - kBlock, kBlock);
      const int col = static_cast<int>(local % kBlock);
      if ((local & 511) == 0) {
        if (begin == 0 && !progress.update("mean-value coordinates", double(p) / std::max<long>(1, end))) {
          stop = true;
          fail(p, cancelled_status("mean-value coordinates"));
        }
        if (stop) return;
      }
#if MM_MVC_PAIRS
      // Two points at once, one per SIMD lane: the same operations in the same order as for
      // one point, so the same bits. A pair with a point at a vertex or in a face's plane is
      // done one point at a time.
      if (p + 1 < end && col % 2 == 0) {
        const MvcPair x = {P(p, 0), P(p + 1, 0)}, y = {P(p, 1), P(p + 1, 1)}, z = {P(p, 2), P(p + 1, 2)};
        if (mvc_weights(cage, x, y, z, &two, [](int) { return false; }) == kMvcAllFaces) {
          double sum0 = 0, sum1 = 0;
          for (int j = 0; j < nc; ++j) sum0 += two.w[j][0], sum1 += two.w[j][1];
          if (!finish(p, col, sum0, [&](int j) { return two.w[j][0]; })) return;
          if (!finish(p + 1, col + 1, sum1, [&](int j) { return two.w[j][1]; })) return;
          p += 2;
          continue;
        }
        if (!single(p, col) || !single(p + 1, col + 1)) return;
        p += 2;
        continue;
      }
#endif
      if (!single(p, col)) return;
      ++p;
    }
    if (end > begin) {
      const long last = begin + (end - 1 - begin) / kBlock * kBlock;
      flush(last, end - last);
    }
  });
  if (!out.status.ok()) return out;
  if (!out.Psi.allFinite()) {
    out.status = Status::error(StatusCode::NumericalError, "mean-value coordinates are not finite");
    return out;
  }
  progress.update("mean-value coordinates", 1.0);
  return out;
}

}  // namespace mm
