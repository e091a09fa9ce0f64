#include "edit/laplacian_editor_impl.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "common/threads.h"
#include "linalg/iterative_refinement.h"
#include "mesh/topology.h"

namespace mm {

using namespace edit_detail;

// Implicit deformation gradients of every center whose gradient may involve an unknown (Eq. 8
// displaces degenerate stencils); Vd is the displaced rest mesh used by stage 1.
Status LaplacianEditor::Impl::build_stencils(const Eigen::MatrixXi& F, EditBuild* s, const Progress& progress) {
  const std::vector<int>& U = s->U;
  const auto& adj = s->adj;
  auto& clock = s->clock;
  const bool implicit = s->implicit = opt.method == EditMethod::Implicit;
  const int r = s->r = opt.coherence_rings;
  if (implicit) {
    // Candidates: every center whose gradient may involve an unknown (stencils reach at most two
    // rings when widened) plus their coherence partners.
    const std::vector<int> candidates = k_ring(adj, U, r + 2);
    ImplicitGradientOptions gopt;
    gopt.condition_threshold = opt.condition_threshold;
    gopt.displacement_scale = opt.displacement_scale;
    grads = implicit_gradients(V, F, adj, candidates, gopt);
    if (!grads.status.ok()) return grads.status;
    Vd = grads.V_displaced;
  } else {
    Vd = V;
  }
  if (!progress.update("edit: stencils", 0.05)) return cancelled_status("edit: stencils");
  stats.stencil_ms = edit_lap_ms(&clock);

  return Status::success();
}

// Stage 1 (paper 001 Sec. 3): minimise E_L + E_R (Eq. 5, 6) subject to the handles (Eq. 7) over
// the unknowns, with the per-vertex linear parts M_i implicit in the positions (Sec. 3.2). Builds
// and factors the normal equations AᵀA (hard constraints eliminated).
Status LaplacianEditor::Impl::build_similarity_system(EditBuild& s, const Progress& progress) {
  const int n = s.n, r = s.r;
  const bool cot = s.cot;
  const double h = s.h;
  const auto& adj = s.adj;
  const std::vector<int>& gid = s.gid;
  const std::vector<int>& pair_centers = s.pair_centers;
  const std::vector<int>& center_index = s.center_index;
  const std::vector<char>& is_active = s.is_active;
  auto& clock = s.clock;
  // ---- stage 1 normal equations N = AᵀA over local numbering (same for x, y, z).
  EditSparse W1;
  Eigen::VectorXd ds1;
  laplacian_rows(s, Vd, &W1, &ds1);
  Eigen::MatrixXd Xd(nL, 3);
  for (int l = 0; l < nL; ++l) Xd.row(l) = Vd.row(l2g[l]);
  // E_L rows (Eq. 5), dimensionless: s·(D_i − (K_i δ_i)ᵀ) with δ_i = D_i v' the rest LC on the
  // displaced mesh and s = h (cotangent, D ~ 1/length²) or 1/h (uniform, D ~ 1).
  const double lscale = cot ? h : 1.0 / h;
  const Eigen::MatrixXd W1X = W1 * Xd;
  std::vector<EditTriplet> t;
  for (int l = 0; l < nU; ++l) {
    if (!has_row[l]) continue;
    const Eigen::Vector3d delta = ds1[l] * W1X.row(l).transpose();
    const int c = center_of[l];
    for (int e = grads.offsets[c]; e < grads.offsets[c + 1]; ++e)
      t.emplace_back(l, stencil_local[e], -lscale * grads.weights.row(e).dot(delta));
  }
  EditSparse E(nU, nL);
  E.setFromTriplets(t.begin(), t.end());
  {
    Eigen::VectorXd s = lscale * ds1;
    for (int l = 0; l < nU; ++l)
      if (!has_row[l]) s[l] = 0;
    E += s.asDiagonal() * W1;
  }
  if (!progress.update("edit: assembling", 0.15)) return cancelled_status("edit: assembling");

  // E_R (Eq. 6) over SF = pairs within r rings, at least one of them active. With S_p the
  // stencil weights of center p (rows of K_p) and G the pair-graph Laplacian,
  //   Σ_pairs ||M_a − M_b||²_F = Σ_c xᵀ K_c G K_cᵀ x,
  // so column i of the E_R block is Σ_{a ∋ i} S_a[i] · Y_a with Y_a = deg_a S_a − Σ_{b~a} S_b.
  // We accumulate every column of the unknowns directly (sparse accumulator), which is much
  // faster than general sparse products and never forms A (17M nonzeros at 50k vertices).
  const int nP = static_cast<int>(pair_centers.size());
  std::vector<int> pidx(n, -1);
  for (int p = 0; p < nP; ++p) pidx[pair_centers[p]] = p;
  std::vector<int> partner_ptr(1, 0), partners;
  {
    std::vector<int> stamp(n, -1), frontier, next;
    for (int p = 0; p < nP; ++p) {
      const int a = pair_centers[p];
      const bool a_active = is_active[center_index[a]];
      frontier.assign(1, a);
      stamp[a] = p;
      for (int d = 1; d <= r; ++d) {
        next.clear();
        for (int v : frontier)
          for (int w : adj[v])
            if (stamp[w] != p) {
              stamp[w] = p;
              next.push_back(w);
              const int q = pidx[w];
              if (q >= 0 && (a_active || is_active[center_index[w]])) partners.push_back(q);
            }
        frontier.swap(next);
      }
      partner_ptr.push_back(static_cast<int>(partners.size()));
    }
  }
  stats.coherence_pairs = static_cast<int>(partners.size() / 2);
  // Kept for the matrix-free residuals of the refinement (stage1_normal_residual).
  pair_center.resize(nP);
  pair_active.resize(nP);
  for (int p = 0; p < nP; ++p) {
    pair_center[p] = center_index[pair_centers[p]];
    pair_active[p] = is_active[pair_center[p]];
  }
  this->partner_ptr = partner_ptr;
  this->partners = partners;
  // Y_a for active centers, as sparse lists (local vertex, 3-vector). The stencils of the pair
  // centers are first packed in pair order (local index and weights side by side), so that
  // summing a center's partners reads one stream instead of four arrays through two indirections.
  struct PackedEntry {
    int j;
    double w[3];
  };
  std::vector<int> pk_ptr(nP + 1, 0);
  for (int p = 0; p < nP; ++p) {
    const int c = center_index[pair_centers[p]];
    pk_ptr[p + 1] = pk_ptr[p] + grads.offsets[c + 1] - grads.offsets[c];
  }
  std::vector<PackedEntry> pk(static_cast<size_t>(pk_ptr[nP]));
  for (int p = 0; p < nP; ++p) {
    const int c = center_index[pair_centers[p]];
    PackedEntry* out = pk.data() + pk_ptr[p];
    for (int e = grads.offsets[c]; e < grads.offsets[c + 1]; ++e, ++out) {
      out->j = stencil_local[e];
      for (int k = 0; k < 3; ++k) out->w[k] = grads.weights(e, k);
    }
  }
  // Y_p is needed only by the columns i of p's stencil, and only at rows j ≥ i < nU (the lower
  // triangle of N_UU). Its entries are kept in buckets between the stencil's sorted indices
  // (a counting sort of ~40 entries into ~8 buckets, instead of sorting them), so a column i
  // reads Y_p from the first bucket at or above i with no search; y_from[x] is that start for
  // the packed stencil entry x of i. Entries below the stencil's smallest index, or known
  // (j ≥ nU), are never read and not kept. Each kept sum is untouched, so N is the same.
  std::vector<double> acc3(3 * static_cast<size_t>(nL), 0.0);
  std::vector<char> mark(nL, 0);
  std::vector<int> touched, bucket_of, thresholds, bucket_start;
  std::vector<int> y_from(pk.size(), 0), y_stop(nP, 0), y_idx;
  std::vector<double> y_val;
  {
    // Reserved at an upper bound (Σ of the stencil sizes over each list's centers) instead of
    // grown: growing copied these lists (~2M entries at 50k vertices) several times over.
    size_t bound = 0, most = 0;
    for (int p = 0; p < nP; ++p) {
      if (!is_active[center_index[pair_centers[p]]]) continue;
      size_t here = static_cast<size_t>(pk_ptr[p + 1] - pk_ptr[p]);
      for (int k = partner_ptr[p]; k < partner_ptr[p + 1]; ++k)
        here += static_cast<size_t>(pk_ptr[partners[k] + 1] - pk_ptr[partners[k]]);
      bound += here;
      most = std::max(most, here);
    }
    y_idx.reserve(bound);
    y_val.reserve(3 * bound);
    touched.resize(most);
    bucket_of.resize(most);
  }
  for (int p = 0; p < nP; ++p) {
    if (!is_active[center_index[pair_centers[p]]]) {
      std::fill(y_from.begin() + pk_ptr[p], y_from.begin() + pk_ptr[p + 1], static_cast<int>(y_idx.size()));
      y_stop[p] = static_cast<int>(y_idx.size());
      continue;
    }
    size_t t = 0;
    auto add_stencil = [&](int q, double g) {
      for (const PackedEntry* x = pk.data() + pk_ptr[q]; x != pk.data() + pk_ptr[q + 1]; ++x) {
        double* a = acc3.data() + 3 * static_cast<size_t>(x->j);
        if (!mark[x->j]) {
          mark[x->j] = 1;
          touched[t++] = x->j;
          a[0] = a[1] = a[2] = 0.0;
        }
        for (int k = 0; k < 3; ++k) a[k] += g * x->w[k];
      }
    };
    add_stencil(p, static_cast<double>(partner_ptr[p + 1] - partner_ptr[p]));
    for (int k = partner_ptr[p]; k < partner_ptr[p + 1]; ++k) add_stencil(partners[k], -1.0);
    for (size_t u = 0; u < t; ++u) mark[touched[u]] = 0;
    // Buckets: b = the number of p's stencil indices ≤ j (0: below them all, not kept).
    thresholds.clear();
    for (int x = pk_ptr[p]; x < pk_ptr[p + 1]; ++x) thresholds.push_back(pk[x].j);
    std::sort(thresholds.begin(), thresholds.end());
    const int m = static_cast<int>(thresholds.size());
    bucket_start.assign(m + 2, 0);
    for (size_t u = 0; u < t; ++u) {
      const int j = touched[u];
      int b = 0;
      if (j < nU)
        while (b < m && thresholds[b] <= j) ++b;
      bucket_of[u] = b;
      ++bucket_start[b + 1];
    }
    const int base = static_cast<int>(y_idx.size());
    bucket_start[1] = 0;  // bucket 0 is dropped
    for (int b = 1; b <= m; ++b) bucket_start[b + 1] += bucket_start[b];
    const int kept = bucket_start[m + 1];
    y_idx.resize(static_cast<size_t>(base + kept));
    y_val.resize(3 * static_cast<size_t>(base + kept));
    for (int x = pk_ptr[p]; x < pk_ptr[p + 1]; ++x) {
      const int rank = static_cast<int>(std::lower_bound(thresholds.begin(), thresholds.end(), pk[x].j) - thresholds.begin());
      y_from[x] = base + bucket_start[rank + 1];
    }
    for (size_t u = 0; u < t; ++u) {
      const int b = bucket_of[u];
      if (b == 0) continue;
      const size_t at = static_cast<size_t>(base + bucket_start[b]++);
      const int j = touched[u];
      y_idx[at] = j;
      for (int k = 0; k < 3; ++k) y_val[3 * at + k] = opt.coherence_weight * acc3[3 * j + k];
    }
    y_stop[p] = base + kept;
  }
  // Reverse index: for each unknown, the (pair center, packed stencil entry) pairs that contain it.
  std::vector<int> rev_ptr(nU + 1, 0), rev_center, rev_entry;
  for (const PackedEntry& x : pk)
    if (x.j < nU) ++rev_ptr[x.j + 1];
  for (int i = 0; i < nU; ++i) rev_ptr[i + 1] += rev_ptr[i];
  rev_center.resize(rev_ptr[nU]);
  rev_entry.resize(rev_ptr[nU]);
  {
    std::vector<int> fill(rev_ptr.begin(), rev_ptr.end() - 1);
    for (int p = 0; p < nP; ++p)
      for (int x = pk_ptr[p]; x < pk_ptr[p + 1]; ++x) {
        const int i = pk[x].j;
        if (i >= nU) continue;
        rev_center[fill[i]] = p;
        rev_entry[fill[i]++] = x;
      }
  }
  // Transformation-constraint rows (Eq. 7) at handle vertices whose gradient has an unknown (their
  // right-hand side, the handle's linear part, enters through stage1_normal_residual).
  const double wg = opt.gradient_constraint_weight;
  std::vector<char> grad_row(nP, 0);
  pair_handle.assign(nP, -1);
  if (wg > 0)
    for (int p = 0; p < nP; ++p) {
      const int v = pair_centers[p], c = center_index[v];
      if (gid[v] < 0 || !is_active[c]) continue;
      grad_row[p] = 1;
      pair_handle[p] = gid[v];
    }
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Erow = E;  // rows of E
  const EditSparse& Ecol = E;                                        // columns of E
  // Columns of N = AᵀA for the unknowns: lower part of N_UU. (The known columns N_UK are not
  // needed: right-hand sides are residuals of the unsquared system.) Only rows j ≥ i are summed:
  // the Y_a lists and E's rows are sorted, so each starts at the diagonal (binary search); every
  // kept entry sums the same terms in the same order as the full column would.
  // Columns [c0, c1) into CSC pieces (row indices and values per column, ascending). The
  // columns are independent: natively, with a second thread, the two halves of the unknowns
  // (split where half of the reverse-index entries lie) are summed at once, each with its own
  // accumulator; every entry sums the same terms in the same order either way.
  struct Columns {
    std::vector<int> ptr{0}, rows;
    std::vector<double> vals;
  };
  const int* e_cols = Erow.innerIndexPtr();
  const double* e_vals = Erow.valuePtr();
  auto sum_columns = [&](int c0, int c1, Columns* out) {
    std::vector<double> acc(nL, 0.0);
    std::vector<int> seen(nL, -1), cols_touched;
    out->rows.reserve(static_cast<size_t>(c1 - c0) * 40);
    out->vals.reserve(static_cast<size_t>(c1 - c0) * 40);
    for (int i = c0; i < c1; ++i) {
      cols_touched.clear();
      auto add = [&](int j, double v) {
        if (seen[j] != i) {
          seen[j] = i;
          cols_touched.push_back(j);
          acc[j] = 0.0;
        }
        acc[j] += v;
      };
      for (int k = rev_ptr[i]; k < rev_ptr[i + 1]; ++k) {
        const int p = rev_center[k], x = rev_entry[k];
        const double s0 = pk[x].w[0], s1 = pk[x].w[1], s2 = pk[x].w[2];
        for (int q = y_from[x]; q < y_stop[p]; ++q)
          add(y_idx[q], s0 * y_val[3 * q] + s1 * y_val[3 * q + 1] + s2 * y_val[3 * q + 2]);
        if (grad_row[p])
          for (const PackedEntry* f = pk.data() + pk_ptr[p]; f != pk.data() + pk_ptr[p + 1]; ++f)
            if (f->j >= i) add(f->j, wg * (s0 * f->w[0] + s1 * f->w[1] + s2 * f->w[2]));
      }
      for (EditSparse::InnerIterator er(Ecol, i); er; ++er) {
        const int* row_end = e_cols + Erow.outerIndexPtr()[er.row() + 1];
        for (const int* c = std::lower_bound(e_cols + Erow.outerIndexPtr()[er.row()], row_end, i); c != row_end; ++c)
          add(*c, er.value() * e_vals[c - e_cols]);
      }
      if (soft[i] > 0) add(i, soft[i]);
      std::sort(cols_touched.begin(), cols_touched.end());
      for (int j : cols_touched)
        if (j < nU) out->rows.push_back(j), out->vals.push_back(acc[j]);
      out->ptr.push_back(static_cast<int>(out->rows.size()));
    }
  };
  Columns halves[2];
  int mid = nU;
#if MM_HAS_THREADS
  if (max_threads() > 1 && nU >= 2000) {
    mid = static_cast<int>(std::lower_bound(rev_ptr.begin(), rev_ptr.begin() + nU + 1, rev_ptr[nU] / 2) - rev_ptr.begin());
    mid = std::clamp(mid, 1, nU - 1);
    Task second([&] { sum_columns(mid, nU, &halves[1]); });
    sum_columns(0, mid, &halves[0]);
    second.wait();
  }
#endif
  if (mid == nU) sum_columns(0, nU, &halves[0]);
  const size_t nnz = halves[0].rows.size() + halves[1].rows.size();
  EditSparse NUU(nU, nU);
  NUU.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  {
    int* outer = NUU.outerIndexPtr();
    int col = 0;
    int base = 0;
    size_t at = 0;
    for (const Columns& h : halves) {
      for (size_t k = 0; k + 1 < h.ptr.size(); ++k) outer[col++] = base + h.ptr[k];
      std::copy(h.rows.begin(), h.rows.end(), NUU.innerIndexPtr() + at);
      std::copy(h.vals.begin(), h.vals.end(), NUU.valuePtr() + at);
      at += h.rows.size();
      base += static_cast<int>(h.rows.size());
    }
    outer[nU] = static_cast<int>(nnz);
  }
  E1 = std::move(E);

  stats.system_nonzeros = static_cast<long>(NUU.nonZeros());
  stats.assembly_ms = edit_lap_ms(&clock);
  if (!progress.update("edit: factor", 0.35)) return cancelled_status("edit: factor");
  if (Status s = solver1.factor(NUU, progress.sub(0.35, 0.9)); !s.ok())
    return Status::error(s.code, "implicit editing system (Eq. 7): " + s.message +
                                     ". The handles may not determine a rotation: constrain at least 3 "
                                     "non-collinear vertices");
  stats.factor_ms = edit_lap_ms(&clock);
  stats.factor_nonzeros = solver1.factor_entries();
  if (!progress.update("edit: factor", 0.9)) return cancelled_status("edit: factor");

  return Status::success();
}

Eigen::Matrix3d LaplacianEditor::Impl::gradient_local(int l) const {
  // M(Vd + U) = I + M(U): Σ_k v'_k w_kᵀ = I on the displaced rest mesh (Eq. 4), so only the
  // displacements need summing (exact for the identity, and no cancellation of large coordinates).
  const int c = center_of[l];
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  for (int e = grads.offsets[c]; e < grads.offsets[c + 1]; ++e)
    M.noalias() += U1.row(stencil_local[e]).transpose() * grads.weights.row(e);
  return M;
}

// The residual of the normal equations formed from A itself, never from the assembled AᵀA (whose
// rounding is what the refinement removes). Rows of A (for one column y, Sec. 6):
//   E_L (Eq. 5):        (E1 y)_i                               right-hand side 0
//   E_R (Eq. 6):        √cw (m_a(y) − m_b(y))_c, pairs {a, b}  right-hand side 0
//   Eq. 7 gradients:    √wg (m_p(y))_c                          right-hand side √wg B_h(c)
//   soft constraints:   √soft_i y_i                             right-hand side √soft_i t_i
// with m_a(y) = Σ_k w_k y_k over the stencil of a (a 3-vector: row r of M_a for coordinate r).
// Hence Aᵀ(b − A y) = −E1ᵀ E1 y − cw Σ_a K_a Z_a − wg Σ_p K_p (m_p − B_h) + soft (t − y), with
// Z_a = Σ_{b ~ a} (m_a − m_b) over a's partners (each unordered pair is listed from both ends).
namespace {

// The E_R and gradient-constraint part of stage1_normal_residual over row-major m-column blocks.
// M = m at compile time (3: a drag, 4 or 8: the basis of 1 or 2 handles) lets the compiler unroll
// and vectorise the 3-by-m block loops (they are most of the residual's cost); 0 = any m.
struct ResidualPairs {
  int nP, nU, m;
  const int *pair_center, *offsets, *stencil_local, *partner_ptr, *partners, *pair_handle;
  const char* pair_active;
  const double* weights;  // column-major #entries by 3
  long wstride;
  double cw, wg;
  const std::vector<Eigen::MatrixXd>* grad_rhs;
};

// first/second (optional, ascending): the pairs whose m_p can be nonzero and those whose Z_p or
// gradient-constraint rows can be — all pairs when null (see ZeroStartLists).
template <int M>
void residual_pairs(const ResidualPairs& a, const double* Y, double* Mg, double* G,
                    const std::vector<int>* first = nullptr, const std::vector<int>* second = nullptr) {
  const int m = M > 0 ? M : a.m;
  const int n1 = first ? static_cast<int>(first->size()) : a.nP;
  for (int i1 = 0; i1 < n1; ++i1) {
    const int p = first ? (*first)[static_cast<size_t>(i1)] : i1;
    const int c = a.pair_center[p];
    double* M0 = Mg + 3 * static_cast<long>(p) * m;
    double *M1 = M0 + m, *M2 = M1 + m;
    for (int e = a.offsets[c]; e < a.offsets[c + 1]; ++e) {
      const double w0 = a.weights[e], w1 = a.weights[e + a.wstride], w2 = a.weights[e + 2 * a.wstride];
      const double* y = Y + static_cast<long>(a.stencil_local[e]) * m;
      for (int k = 0; k < m; ++k) {
        M0[k] += w0 * y[k];
        M1[k] += w1 * y[k];
        M2[k] += w2 * y[k];
      }
    }
  }
  std::vector<double> Zbuf(3 * static_cast<size_t>(m));
  double* Z = Zbuf.data();
  const int n2 = second ? static_cast<int>(second->size()) : a.nP;
  for (int i2 = 0; i2 < n2; ++i2) {
    const int p = second ? (*second)[static_cast<size_t>(i2)] : i2;
    if (!a.pair_active[p]) continue;  // its stencil has no unknown: no column of A_U to feed
    const double* Mp = Mg + 3 * static_cast<long>(p) * m;
    const int deg = a.partner_ptr[p + 1] - a.partner_ptr[p];
    // Z = Σ_q (M_p − M_q) = deg·M_p − Σ_q M_q (the sum first: fewer operations per partner).
    for (int k = 0; k < 3 * m; ++k) Z[k] = 0.0;
    for (int q = a.partner_ptr[p]; q < a.partner_ptr[p + 1]; ++q) {
      const double* Mq = Mg + 3 * static_cast<long>(a.partners[q]) * m;
      for (int k = 0; k < 3 * m; ++k) Z[k] += Mq[k];
    }
    for (int k = 0; k < 3 * m; ++k) Z[k] = a.cw * (deg * Mp[k] - Z[k]);
    if (a.pair_handle[p] >= 0) {
      const Eigen::MatrixXd& B = (*a.grad_rhs)[a.pair_handle[p]];  // 3 by m
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < m; ++k) Z[r * m + k] += a.wg * (Mp[r * m + k] - B(r, k));
    }
    const int c = a.pair_center[p];
    for (int e = a.offsets[c]; e < a.offsets[c + 1]; ++e) {
      const int j = a.stencil_local[e];
      if (j >= a.nU) continue;
      const double w0 = a.weights[e], w1 = a.weights[e + a.wstride], w2 = a.weights[e + 2 * a.wstride];
      double* gj = G + static_cast<long>(j) * m;
      for (int k = 0; k < m; ++k) gj[k] -= w0 * Z[k] + w1 * Z[m + k] + w2 * Z[2 * m + k];
    }
  }
}

}  // namespace

void LaplacianEditor::Impl::build_zero_start_lists() {
  // Pairs whose gradient reads a constrained vertex (m_p ≠ 0 when only those move) ...
  const int nP = static_cast<int>(pair_center.size());
  std::vector<char> in1(static_cast<size_t>(nP), 0);
  zero_start.first.clear();
  zero_start.second.clear();
  for (int p = 0; p < nP; ++p) {
    const int c = pair_center[p];
    for (int e = grads.offsets[c]; e < grads.offsets[c + 1] && !in1[static_cast<size_t>(p)]; ++e)
      if (stencil_local[e] >= nU) in1[static_cast<size_t>(p)] = 1;
    if (in1[static_cast<size_t>(p)]) zero_start.first.push_back(p);
  }
  // ... and those whose E_R difference or gradient-constraint rows can then be nonzero.
  for (int p = 0; p < nP; ++p) {
    bool any = in1[static_cast<size_t>(p)] || (opt.gradient_constraint_weight > 0 && pair_handle[p] >= 0);
    for (int q = partner_ptr[p]; q < partner_ptr[p + 1] && !any; ++q) any = in1[static_cast<size_t>(partners[q])];
    if (any) zero_start.second.push_back(p);
  }
  // E_L rows that read a constrained vertex, restricted to the unknowns' columns (transposed).
  const edit_detail::EditSparse EK = E1.rightCols(E1.cols() - nU);
  std::vector<char> row_in(static_cast<size_t>(E1.rows()), 0);
  for (int k = 0; k < EK.outerSize(); ++k)
    for (edit_detail::EditSparse::InnerIterator it(EK, k); it; ++it) row_in[static_cast<size_t>(it.row())] = 1;
  zero_start.rows.clear();
  std::vector<int> slot(static_cast<size_t>(E1.rows()), -1);
  for (size_t r = 0; r < row_in.size(); ++r)
    if (row_in[r]) slot[r] = static_cast<int>(zero_start.rows.size()), zero_start.rows.push_back(static_cast<int>(r));
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < nU; ++j)
    for (edit_detail::EditSparse::InnerIterator it(E1, j); it; ++it)
      if (slot[static_cast<size_t>(it.row())] >= 0) t.emplace_back(slot[static_cast<size_t>(it.row())], j, it.value());
  zero_start.E1U.resize(static_cast<Eigen::Index>(zero_start.rows.size()), nU);
  zero_start.E1U.setFromTriplets(t.begin(), t.end());
  zero_start.ready = true;
}

void LaplacianEditor::Impl::stage1_normal_residual(const Eigen::MatrixXd& Y, const std::vector<Eigen::MatrixXd>& grad_rhs,
                                                   const Eigen::MatrixXd& soft_target, Eigen::MatrixXd* g,
                                                   bool unknowns_zero) {
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const int m = static_cast<int>(Y.cols());
  const int nP = static_cast<int>(pair_center.size());
  RowMat G;
  if (unknowns_zero) {
    // The first residual of a solve from x = 0 (a drag's right-hand side): only the constrained
    // rows of Y move, so only the E_L rows and pairs near them contribute — the terms left out
    // are exact zeros. Costs ~the constrained region instead of the whole mesh.
    if (!zero_start.ready) build_zero_start_lists();
    const Eigen::MatrixXd EY = E1.rightCols(E1.cols() - nU) * Y.bottomRows(Y.rows() - nU);
    Eigen::MatrixXd EYr(static_cast<Eigen::Index>(zero_start.rows.size()), m);
    for (size_t r = 0; r < zero_start.rows.size(); ++r) EYr.row(static_cast<Eigen::Index>(r)) = EY.row(zero_start.rows[r]);
    G = -(zero_start.E1U.transpose() * EYr);
  } else {
    const Eigen::MatrixXd EY = E1 * Y;
    G = -(E1.transpose() * EY).topRows(nU);
  }
  const RowMat Yr = Y;
  RowMat Mg = RowMat::Zero(3 * static_cast<Eigen::Index>(nP), m);
  const ResidualPairs a{nP, nU, m, pair_center.data(), grads.offsets.data(), stencil_local.data(), partner_ptr.data(),
                        partners.data(), pair_handle.data(), pair_active.data(), grads.weights.data(),
                        static_cast<long>(grads.weights.rows()), opt.coherence_weight, opt.gradient_constraint_weight,
                        &grad_rhs};
  const std::vector<int>* l1 = unknowns_zero ? &zero_start.first : nullptr;
  const std::vector<int>* l2 = unknowns_zero ? &zero_start.second : nullptr;
  if (m == 3) residual_pairs<3>(a, Yr.data(), Mg.data(), G.data(), l1, l2);
  else if (m == 4) residual_pairs<4>(a, Yr.data(), Mg.data(), G.data(), l1, l2);
  else if (m == 8) residual_pairs<8>(a, Yr.data(), Mg.data(), G.data(), l1, l2);
  else residual_pairs<0>(a, Yr.data(), Mg.data(), G.data(), l1, l2);
  if (soft_target.size())
    for (int l = 0; l < nU; ++l)
      if (soft[l] > 0) G.row(l) += soft[l] * (soft_target.row(l) - Y.row(l));
  *g = G;
}

Status LaplacianEditor::Impl::solve_stage1(const Eigen::MatrixXd& known_u, const Eigen::MatrixXd& soft_u_d,
                                           const std::vector<Eigen::Matrix3d>& linear_parts,
                                           const std::vector<Eigen::Vector3d>* translation, int* refinements,
                                           int max_refinements) {
  linear = linear_parts;
  *refinements = 0;
  U1.resize(nL, 3);
  U1.bottomRows(nL - nU) = known_u;
  if (translation && have_basis) {
    // Superposition of the precomputed (refined) responses: u_U = Σ_h Φ_h [(A_h − I) τ_h]ᵀ.
    Eigen::MatrixXd uU = Eigen::MatrixXd::Zero(nU, 3);
    for (int h = 0; h < num_handles; ++h) {
      const Eigen::Matrix3d B = linear_parts[h] - Eigen::Matrix3d::Identity();
      Eigen::Matrix<double, 4, 3> T;
      T.topRows(3) = B.transpose();
      T.row(3) = (B * handle_center[h] + (*translation)[h]).transpose();
      uU.noalias() += Phi[h] * T;
    }
    U1.topRows(nU) = uU;
    return Status::success();
  }
  // Eliminated hard constraints, one column per coordinate (Sec. 6): the first solve and its
  // refinements all use residuals of the unsquared system.
  std::vector<Eigen::MatrixXd> grad_rhs;
  if (opt.gradient_constraint_weight > 0)
    for (int h = 0; h < num_handles; ++h) grad_rhs.push_back((linear_parts[h] - Eigen::Matrix3d::Identity()).transpose());
  Eigen::MatrixXd Y = U1, x = Eigen::MatrixXd::Zero(nU, 3);
  bool from_zero = true;  // refine_solution starts from x = 0
  const IterativeRefinementReport rep = refine_solution(
      [&](const Eigen::MatrixXd& xx, Eigen::MatrixXd* g) {
        Y.topRows(nU) = xx;
        stage1_normal_residual(Y, grad_rhs, soft_u_d, g, from_zero);
        from_zero = false;
      },
      [&](Eigen::MatrixXd* r) { solver1.solve_in_place(*r); }, &x,
      max_refinements >= 0 ? max_refinements : opt.residual_refinements);
  if (!rep.status.ok()) return rep.status;
  U1.topRows(nU) = x;
  *refinements = rep.steps;
  return Status::success();
}

EditResult LaplacianEditor::Impl::output_stage1(int refinements) {
  EditResult out;
  out.refinements = refinements;
  out.V = V;
  // Unknowns: rest + displacement (Vd = V where nothing was displaced).
  for (int l = 0; l < nU; ++l) out.V.row(l2g[l]) += U1.row(l);
  for (int k = 0; k < nL - nU; ++k) out.V.row(l2g[nU + k]) = known.row(k);
  // Pull-back of displaced free vertices (Sec. 3.3): ṽ = M (v − v') + ṽ' = v + u + (M − I)(v − v').
  // A soft-constrained one uses its handle's linear part instead (its target was set as A v' + t),
  // so that soft constraints tend to hard ones as their weight grows.
  for (int l : displaced_unknowns) {
    const int v = l2g[l], g = group[l];
    const Eigen::Matrix3d M = g == -2 ? gradient_local(l) : g == -1 ? Eigen::Matrix3d::Identity() : linear[g];
    out.V.row(v) = (V.row(v) + U1.row(l)).transpose() + (M - Eigen::Matrix3d::Identity()) * (V.row(v) - Vd.row(v)).transpose();
  }
  if (!out.V.allFinite())
    out.status = Status::error(StatusCode::NumericalError, "the editing solve produced non-finite positions");
  return out;
}

}  // namespace mm
