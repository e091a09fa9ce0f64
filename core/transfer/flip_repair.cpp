#include "transfer/flip_repair.h"

#include <algorithm>
#include <chrono>
#include <iterator>
#include <utility>
#include <vector>

#include <Eigen/SparseCore>

#include "linalg/rigid_fit.h"
#include "linalg/spd_solver.h"
#include "mesh/topology.h"
#include "metrics/transfer_metrics.h"
#include "operators/operators.h"

namespace mm {

namespace flip_repair_detail {

struct WeightedEdge {
  int j;
  double w;
};

// Per vertex, its neighbours with the rest shape's cotangent weights, clamped from below so that
// obtuse fans (negative weights) keep the system positive definite.
std::vector<std::vector<WeightedEdge>> rest_weights(const Mesh& rest) {
  const SparseMatrix W = cotan_stiffness(rest.V, rest.F);
  std::vector<std::vector<WeightedEdge>> out(rest.V.rows());
  double sum = 0;
  long count = 0;
  for (int k = 0; k < W.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(W, k); it; ++it)
      if (it.row() != it.col() && -it.value() > 0) {
        sum += -it.value();
        ++count;
      }
  const double floor = 1e-2 * (count ? sum / count : 1.0);
  for (int k = 0; k < W.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(W, k); it; ++it)
      if (it.row() != it.col()) out[it.row()].push_back({static_cast<int>(it.col()), std::max(-it.value(), floor)});
  return out;
}

std::vector<int> face_vertices(const Eigen::MatrixXi& F, const std::vector<int>& faces) {
  std::vector<int> v;
  for (int f : faces)
    for (int k = 0; k < 3; ++k) v.push_back(F(f, k));
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// One solve of `free` (ascending), every other vertex held at X. Per connected component of the
// free set, R is the rotation of the held band around it (`band` rings of held vertices, rest →
// current), and the component is solved from
//   Σ_j w_ij (x_i − x_j) = Σ_j w_ij R (p_i − p_j)      (i free; x_j = X_j for j held)
// — Laplacian editing with one rotation per component: the rest shape's detail, turned like its
// surroundings, between the held positions. membrane: R = 0, the smooth surface spanning the held
// positions (where the rest detail does not fit between them).
Status relax_region(const Mesh& rest, const std::vector<std::vector<WeightedEdge>>& E,
                    const std::vector<std::vector<int>>& adj, const std::vector<int>& free, int band, bool membrane,
                    Eigen::MatrixXd* X) {
  const int n = static_cast<int>(rest.V.rows()), m = static_cast<int>(free.size());
  std::vector<int> local(n, -1);
  for (int a = 0; a < m; ++a) local[free[a]] = a;
  // Components of the free set (through free-free edges), numbered by their smallest vertex.
  std::vector<int> comp(m, -1);
  int ncomp = 0;
  for (int a = 0; a < m; ++a) {
    if (comp[a] >= 0) continue;
    std::vector<int> stack{a};
    comp[a] = ncomp;
    while (!stack.empty()) {
      const int c = stack.back();
      stack.pop_back();
      for (int j : adj[free[c]])
        if (local[j] >= 0 && comp[local[j]] < 0) {
          comp[local[j]] = ncomp;
          stack.push_back(local[j]);
        }
    }
    ++ncomp;
  }
  // Each component's rotation from its held band (the membrane: none, R = 0).
  std::vector<Eigen::Matrix3d> R(ncomp, membrane ? Eigen::Matrix3d::Zero().eval() : Eigen::Matrix3d::Identity().eval());
  for (int c = 0; c < ncomp && !membrane; ++c) {
    std::vector<int> seeds;
    for (int a = 0; a < m; ++a)
      if (comp[a] == c) seeds.push_back(free[a]);
    std::vector<int> ring;
    for (int v : k_ring(adj, seeds, band))
      if (local[v] < 0) ring.push_back(v);
    if (ring.size() < 3) continue;
    Eigen::MatrixXd P(ring.size(), 3), Q(ring.size(), 3);
    for (size_t k = 0; k < ring.size(); ++k) {
      P.row(k) = rest.V.row(ring[k]);
      Q.row(k) = X->row(ring[k]);
    }
    R[c] = fit_rigid(P, Q).R;
  }
  double wsum = 0;
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd B(m, 3);
  for (int a = 0; a < m; ++a) {
    const int i = free[a];
    double d = 0;
    Eigen::RowVector3d b = Eigen::RowVector3d::Zero();
    for (const WeightedEdge& e : E[i]) {
      d += e.w;
      b += e.w * (rest.V.row(i) - rest.V.row(e.j)) * R[comp[a]].transpose();
      if (local[e.j] >= 0)
        trip.emplace_back(a, local[e.j], -e.w);
      else
        b += e.w * X->row(e.j);
    }
    wsum += d;
    trip.emplace_back(a, a, d);
    B.row(a) = b;
  }
  // A weak pull to the current positions keeps the system definite when a component is a whole
  // connected piece of the mesh (nothing held around it).
  const double anchor = 1e-8 * (m ? wsum / m : 1.0);
  for (int a = 0; a < m; ++a) {
    trip.emplace_back(a, a, anchor);
    B.row(a) += anchor * X->row(free[a]);
  }
  SparseMatrix L(m, m);
  L.setFromTriplets(trip.begin(), trip.end());
  SpdSolver solver;
  if (Status s = solver.factor(L); !s.ok()) return s;
  solver.solve_in_place(B);
  if (!B.allFinite()) return Status::error(StatusCode::NumericalError, "flip repair: non-finite positions");
  for (int a = 0; a < m; ++a) X->row(free[a]) = B.row(a);
  return Status{};
}

// The faces a repair must remove: flipped (a local fold) or collapsed (a patch crushed to a
// sheet — what a membrane spanning a protrusion does: the cotangent-harmonic fill of a foot held
// at the shin squeezes the toes by 1e-6 in area, leaving normals that are noise). Both counted,
// ascending and without repeats.
std::vector<int> faulty_faces(const Eigen::MatrixXd& X, const Mesh& rest, const std::vector<std::vector<int>>& fn,
                              int* flipped_count) {
  std::vector<int> f = flipped_faces(X, rest.V, rest.F, fn);
  *flipped_count = static_cast<int>(f.size());
  const std::vector<int> c = collapsed_faces(X, rest.V, rest.F);
  std::vector<int> out;
  std::set_union(f.begin(), f.end(), c.begin(), c.end(), std::back_inserter(out));
  return out;
}

}  // namespace flip_repair_detail

FlipRepairResult repair_flips(const Mesh& rest, const Eigen::MatrixXd& deformed, const FlipRepairOptions& opt,
                              const Progress& progress) {
  using namespace flip_repair_detail;
  const auto t0 = std::chrono::steady_clock::now();
  FlipRepairResult out;
  out.V = deformed;
  const auto fn = face_neighbours(rest.F);
  int flipped_count = 0;
  std::vector<int> faulty = faulty_faces(deformed, rest, fn, &flipped_count);  // of out.V
  out.flipped_before = out.flipped_after = flipped_count;
  out.collapsed_before = out.collapsed_after = static_cast<int>(faulty.size()) - flipped_count;
  if (!faulty.empty() && opt.rounds > 0 && opt.rings >= 0) {
    const auto adj = vertex_adjacency(rest.F, static_cast<int>(rest.V.rows()));
    const auto E = rest_weights(rest);
    for (int r = 0; r < opt.rounds && !faulty.empty(); ++r) {
      if (!progress.update("flip repair", static_cast<double>(r) / opt.rounds)) {
        out.status = cancelled_status("flip repair");
        break;
      }
      // The region: the faces the best result so far still flips (or has collapsed), grown by
      // twice the rings each round.
      const std::vector<int> free = k_ring(adj, face_vertices(rest.F, faulty), opt.rings << r);
      // Both solves; the one leaving fewer faulty faces is kept (the detail one on a tie).
      bool stop = false;
      Eigen::MatrixXd best;
      std::vector<int> best_faulty = faulty;
      int best_flipped = flipped_count;
      bool best_membrane = false;
      for (const bool membrane : {false, true}) {
        Eigen::MatrixXd X = out.V;
        if (Status s = relax_region(rest, E, adj, free, opt.band, membrane, &X); !s.ok()) {
          out.status = s;
          stop = true;
          break;
        }
        int now_flipped = 0;
        std::vector<int> now = faulty_faces(X, rest, fn, &now_flipped);
        if (now.size() < best_faulty.size()) {
          best = std::move(X);
          best_faulty = std::move(now);
          best_flipped = now_flipped;
          best_membrane = membrane;
        }
      }
      if (!stop && best.size() > 0) {
        out.V = std::move(best);
        faulty = std::move(best_faulty);
        flipped_count = best_flipped;
        if (!best_membrane) ++out.detail_rounds;
      }
      ++out.rounds;
      if (stop) break;
    }
    out.flipped_after = flipped_count;
    out.collapsed_after = static_cast<int>(faulty.size()) - flipped_count;
    for (int i = 0; i < out.V.rows(); ++i) out.moved_vertices += out.V.row(i) != deformed.row(i);
  }
  out.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace mm
