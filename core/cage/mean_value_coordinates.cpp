#include "cage/mean_value_coordinates.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <vector>

#include "common/threads.h"

namespace mm {

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
  parallel_blocks(np, 1024, [&](long begin, long end) {
    // Filled column by column (one point per column, contiguous) into a small block that is
    // copied transposed into the rows of Psi every kBlock points: writing the rows of a
    // column-major #P × #C matrix directly is strided and was most of the time, and a full
    // #C × #P transpose buffer (80 MB for 22k points and 450 cage vertices) cost another ~0.1 s.
    constexpr int kBlock = 32;
    Eigen::MatrixXd PsiT(nc, kBlock);
    auto flush = [&](long first, long count) {
      out.Psi.middleRows(first, count) = PsiT.leftCols(count).transpose();
    };
    std::vector<double> ux(nc), uy(nc), uz(nc), d(nc), w(nc), inv_d(nc);
    std::vector<double> th(ne), sn(ne), cs(ne), inv_sn(ne);
    for (long p = begin; p < end; ++p) {
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
      const double x = P(p, 0), y = P(p, 1), z = P(p, 2);
      int at_vertex = -1;
      for (int j = 0; j < nc; ++j) {
        const double ex = C(j, 0) - x, ey = C(j, 1) - y, ez = C(j, 2) - z;
        const double dj = std::sqrt(ex * ex + ey * ey + ez * ez);
        if (dj < vertex_eps) {
          at_vertex = j;
          break;
        }
        d[j] = dj;
        inv_d[j] = 1.0 / dj;
        ux[j] = ex * inv_d[j];
        uy[j] = ey * inv_d[j];
        uz[j] = ez * inv_d[j];
      }
      if (at_vertex >= 0) {
        PsiT.col(col).setZero();
        PsiT(at_vertex, col) = 1.0;
        continue;
      }
      for (int e = 0; e < ne; ++e) {
        const int a = edges[e][0], b = edges[e][1];
        const double dx = ux[a] - ux[b], dy = uy[a] - uy[b], dz = uz[a] - uz[b];
        const double l = std::sqrt(dx * dx + dy * dy + dz * dz);
        const double half = std::min(1.0, 0.5 * l);
        th[e] = 2.0 * std::asin(half);
        sn[e] = 2.0 * half * std::sqrt(std::max(0.0, 1.0 - half * half));
        cs[e] = 1.0 - 2.0 * half * half;
        inv_sn[e] = 1.0 / sn[e];  // divisions hoisted out of the face loop (most of its time)
      }
      std::fill(w.begin(), w.end(), 0.0);
      bool on_face = false;
      for (int f = 0; f < nf && !on_face; ++f) {
        const int i0 = CF(f, 0), i1 = CF(f, 1), i2 = CF(f, 2);
        const int e0 = face_edge[f][0], e1 = face_edge[f][1], e2 = face_edge[f][2];
        const double det = ux[i0] * (uy[i1] * uz[i2] - uz[i1] * uy[i2]) -
                           uy[i0] * (ux[i1] * uz[i2] - uz[i1] * ux[i2]) +
                           uz[i0] * (ux[i1] * uy[i2] - uy[i1] * ux[i2]);
        const double t0 = th[e0], t1 = th[e1], t2 = th[e2];
        if (std::abs(det) < 1e-10) {
          const double h = 0.5 * (t0 + t1 + t2);
          if (kPi - h < 1e-7) {
            // On the face: 2D barycentric coordinates (JSW Fig. 4).
            std::fill(w.begin(), w.end(), 0.0);
            w[i0] = sn[e0] * d[i2] * d[i1];
            w[i1] = sn[e1] * d[i0] * d[i2];
            w[i2] = sn[e2] * d[i1] * d[i0];
            on_face = true;
          }
          continue;  // in the face's plane but outside it: no contribution
        }
        const double s0 = sn[e0], s1 = sn[e1], s2 = sn[e2];
        const double c0 = cs[e0], c1 = cs[e1], c2 = cs[e2];
        const double is0 = inv_sn[e0], is1 = inv_sn[e1], is2 = inv_sn[e2];
        const double C0 = (c0 - c1 * c2) * (is1 * is2);
        const double C1 = (c1 - c2 * c0) * (is2 * is0);
        const double C2 = (c2 - c0 * c1) * (is0 * is1);
        const double inv_det = 1.0 / det;
        w[i0] += s0 * (t0 - C1 * t2 - C2 * t1) * (inv_d[i0] * inv_det);
        w[i1] += s1 * (t1 - C2 * t0 - C0 * t2) * (inv_d[i1] * inv_det);
        w[i2] += s2 * (t2 - C0 * t1 - C1 * t0) * (inv_d[i2] * inv_det);
      }
      double sum = 0;
      for (int j = 0; j < nc; ++j) sum += w[j];
      if (!(std::abs(sum) > 0) || !std::isfinite(sum)) {
        fail(p, Status::error(StatusCode::NumericalError,
                              "mean-value weights of point " + std::to_string(p) + " cancel (is it inside the cage?)"));
        return;
      }
      const double inv = 1.0 / sum;
      for (int j = 0; j < nc; ++j) PsiT(j, col) = w[j] * inv;
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
