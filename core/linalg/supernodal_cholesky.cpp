#include "linalg/supernodal_cholesky.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>

#include "common/threads.h"

#if defined(__wasm_simd128__)
#include <wasm_simd128.h>
#endif

namespace mm {

namespace supernodal_detail {

using SnSparse = Eigen::SparseMatrix<double>;

// Lower (or, with `upper`, upper) triangle of P A Pᵀ, where row/column i of A becomes p[i]: one
// counting sort by column, O(nnz). Row indices within a column are left in the order A's entries
// come in (not sorted): everything below reads columns as sets (the elimination tree, the counts,
// the row structure, and the assembly, where each position receives exactly one value).
SnSparse sn_permuted_triangle(const SnSparse& A, const std::vector<int>& p, bool upper) {
  const int n = static_cast<int>(A.cols());
  std::vector<int> count(n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (SnSparse::InnerIterator it(A, j); it; ++it)
      if (it.row() >= j) ++count[(upper ? std::max(p[it.row()], p[j]) : std::min(p[it.row()], p[j])) + 1];
  for (int j = 0; j < n; ++j) count[j + 1] += count[j];
  SnSparse C(n, n);
  C.resizeNonZeros(count[n]);
  std::copy(count.begin(), count.end(), C.outerIndexPtr());
  int* fill = count.data();
  for (int j = 0; j < n; ++j)
    for (SnSparse::InnerIterator it(A, j); it; ++it) {
      if (it.row() < j) continue;  // only the lower triangle is read
      const int a = p[it.row()], b = p[j];
      const int col = upper ? std::max(a, b) : std::min(a, b);
      const int k = fill[col]++;
      C.innerIndexPtr()[k] = upper ? std::min(a, b) : std::max(a, b);
      C.valuePtr()[k] = it.value();
    }
  return C;
}

// Elimination tree (Liu's algorithm with path compression) from the upper triangle U (CSC).
std::vector<int> sn_elimination_tree(const SnSparse& U) {
  const int n = static_cast<int>(U.cols());
  std::vector<int> parent(n, -1), ancestor(n, -1);
  for (int k = 0; k < n; ++k)
    for (SnSparse::InnerIterator it(U, k); it; ++it) {
      for (int i = static_cast<int>(it.row()); i != -1 && i < k;) {
        const int next = ancestor[i];
        ancestor[i] = k;
        if (next == -1) parent[i] = k;
        i = next;
      }
    }
  return parent;
}

// Off-diagonal column counts of the Cholesky factor of a matrix whose lower triangle is C (CSC,
// rows ≥ the column), numbered so that the identity is a postorder of its elimination tree
// `parent`: Gilbert, Ng & Peyton's skeleton-leaf method (as in Davis, "Direct methods for sparse
// linear systems", Sec. 4.5), O(nnz(C) α(n)) instead of the O(nnz(L)) row-subtree walk; the same
// counts. Each column j starts at 1 if it is a leaf of the tree; every row i whose subtree j is a
// new leaf of adds 1 at j and, when j is not i's first leaf, removes 1 at the least common
// ancestor of j and i's previous leaf; the counts are then summed up the tree.
std::vector<int> sn_column_counts(const SnSparse& C, const std::vector<int>& parent) {
  const int n = static_cast<int>(C.cols());
  std::vector<int> delta(n, 0), first(n, -1), maxfirst(n, -1), prevleaf(n, -1), ancestor(n);
  for (int k = 0; k < n; ++k) {
    delta[k] = first[k] == -1 ? 1 : 0;  // k is a leaf: no descendant set first[k]
    for (int j = k; j != -1 && first[j] == -1; j = parent[j]) first[j] = k;
  }
  for (int i = 0; i < n; ++i) ancestor[i] = i;
  for (int j = 0; j < n; ++j) {
    if (parent[j] != -1) --delta[parent[j]];
    for (SnSparse::InnerIterator it(C, j); it; ++it) {
      const int i = static_cast<int>(it.row());
      // Is j a leaf of row i's subtree (entry (i, j) of L in the tree's skeleton)?
      if (i <= j || first[j] <= maxfirst[i]) continue;
      maxfirst[i] = first[j];
      const int jprev = prevleaf[i];
      prevleaf[i] = j;
      ++delta[j];
      if (jprev == -1) continue;  // i's first leaf
      int q = jprev;
      while (q != ancestor[q]) q = ancestor[q];
      for (int s = jprev; s != q;) {  // path compression
        const int up = ancestor[s];
        ancestor[s] = q;
        s = up;
      }
      --delta[q];  // the paths from j and jprev to i overlap above their common ancestor q
    }
    if (parent[j] != -1) ancestor[j] = parent[j];
  }
  for (int j = 0; j < n; ++j)
    if (parent[j] != -1) delta[parent[j]] += delta[j];
  for (int j = 0; j < n; ++j) --delta[j];  // off-diagonal
  return delta;
}

// Postorder of a forest: order[k] = the node visited k-th (children in increasing order).
std::vector<int> sn_postorder(const std::vector<int>& parent) {
  const int n = static_cast<int>(parent.size());
  std::vector<int> head(n, -1), next(n, -1), order;
  order.reserve(n);
  for (int j = n - 1; j >= 0; --j)
    if (parent[j] != -1) {
      next[j] = head[parent[j]];
      head[parent[j]] = j;
    }
  std::vector<int> stack;
  for (int root = 0; root < n; ++root) {
    if (parent[root] != -1) continue;
    stack.push_back(root);
    while (!stack.empty()) {
      const int p = stack.back();
      const int child = head[p];
      if (child == -1) {
        stack.pop_back();
        order.push_back(p);
      } else {
        head[p] = next[child];
        stack.push_back(child);
      }
    }
  }
  return order;
}

// Whether merging keeps the block dense enough (CHOLMOD's default relaxation: always for ≤ 4
// columns, then ≤ 80% / 10% / 5% explicit zeros for ≤ 16 / ≤ 48 / more columns). Merged
// supernodes trade a few stored zeros for much larger dense kernels.
bool sn_relax_merge(int ncols, double zero_fraction) {
  if (ncols <= 4) return true;
  if (ncols <= 16) return zero_fraction < 0.8;
  if (ncols <= 48) return zero_fraction < 0.1;
  return zero_fraction < 0.05;
}

#if defined(__wasm_simd128__)
// C −= A Aᵀ on C's lower triangle, C n by n and A n by k (both column-major, strides ldc and
// lda): the front's rank update in WebAssembly, where Eigen 3.4 has no packet math and its
// GEMM runs scalar. A is copied into panels of 4 rows (k × 4, contiguous); each 4 × 4 block of C
// keeps its sums in eight f64x2 registers over k. Every entry sums its k products in order, then
// is subtracted once (natively Eigen's GEMM blocks differently: the last bits differ).
void sn_rank_update_lower_simd(double* C, long ldc, const double* A, long lda, int n, int k, std::vector<double>& pack) {
  const int nb = (n + 3) / 4;
  pack.assign(static_cast<size_t>(nb) * k * 4, 0.0);
  for (int b = 0; b < nb; ++b) {
    const int r0 = 4 * b, rn = std::min(4, n - r0);
    double* pb = pack.data() + static_cast<size_t>(b) * k * 4;
    for (int q = 0; q < k; ++q)
      for (int r = 0; r < rn; ++r) pb[4 * q + r] = A[q * lda + r0 + r];
  }
  for (int jb = 0; jb < nb; ++jb) {
    const double* pj = pack.data() + static_cast<size_t>(jb) * k * 4;
    for (int ib = jb; ib < nb; ++ib) {
      const double* pi = pack.data() + static_cast<size_t>(ib) * k * 4;
      v128_t c[4][2];
      for (int q = 0; q < 4; ++q) c[q][0] = c[q][1] = wasm_f64x2_splat(0.0);
      for (int q = 0; q < k; ++q) {
        const v128_t a0 = wasm_v128_load(pi + 4 * q), a1 = wasm_v128_load(pi + 4 * q + 2);
        for (int t = 0; t < 4; ++t) {
          const v128_t b = wasm_f64x2_splat(pj[4 * q + t]);
          c[t][0] = wasm_f64x2_add(c[t][0], wasm_f64x2_mul(a0, b));
          c[t][1] = wasm_f64x2_add(c[t][1], wasm_f64x2_mul(a1, b));
        }
      }
      double out[4][4];
      for (int t = 0; t < 4; ++t) {
        wasm_v128_store(&out[t][0], c[t][0]);
        wasm_v128_store(&out[t][2], c[t][1]);
      }
      for (int t = 0; t < 4 && 4 * jb + t < n; ++t) {
        const int col = 4 * jb + t;
        for (int r = 0; r < 4 && 4 * ib + r < n; ++r) {
          const int row = 4 * ib + r;
          if (row >= col) C[col * ldc + row] -= out[t][r];
        }
      }
    }
  }
}
#endif

}  // namespace supernodal_detail

using namespace supernodal_detail;

Status SupernodalCholesky::factor(const Eigen::SparseMatrix<double>& A, const Progress& progress) {
  factored_ = false;
  if (A.rows() != A.cols()) return Status::error(StatusCode::InvalidArgument, "system matrix must be square");
  n_ = static_cast<int>(A.rows());
  const int n = n_;
  perm_.assign(n, 0);
  start_.assign(1, 0);
  rows_ptr_.assign(1, 0);
  rows_.clear();
  value_ptr_.assign(1, 0);
  values_.reset();
  values_size_ = 0;
  top_.clear();
  first_.clear();
  bins_[0].clear();
  bins_[1].clear();
  if (n == 0) {
    factored_ = true;
    return Status::success();
  }

  // ---- ordering: AMD, then a sn_postorder of the elimination tree (same fill, contiguous subtrees).
  {
    // AMD's input: A's full symmetric pattern with its diagonal, entries in the order Eigen's
    // self-adjoint AMD overload writes them (so the same ordering), as a pattern only (one byte
    // of "value" per entry instead of a copy of A's doubles) and with the elbow room AMD works
    // in reserved up front (it would reallocate and copy the pattern).
    std::vector<int> count(n + 1, 0);
    for (int j = 0; j < n; ++j)
      for (SnSparse::InnerIterator it(A, j); it; ++it) {
        const int i = static_cast<int>(it.row());
        if (i < j) continue;  // only the lower triangle is read
        ++count[j + 1];
        if (i != j) ++count[i + 1];
      }
    for (int j = 0; j < n; ++j) count[j + 1] += count[j];
    const long nnz = count[n];
    Eigen::SparseMatrix<char, Eigen::ColMajor, int> S(n, n);
    S.reserve(nnz + nnz / 5 + 2 * static_cast<long>(n));
    S.resizeNonZeros(nnz);
    std::copy(count.begin(), count.end(), S.outerIndexPtr());
    int* Si = S.innerIndexPtr();
    for (int j = 0; j < n; ++j)
      for (SnSparse::InnerIterator it(A, j); it; ++it) {
        const int i = static_cast<int>(it.row());
        if (i < j) continue;
        Si[count[j]++] = i;
        if (i != j) Si[count[i]++] = j;
      }
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> Pinv;
    Eigen::internal::minimum_degree_ordering(S, Pinv);
    const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P = Pinv.inverse();
    for (int i = 0; i < n; ++i) perm_[i] = P.indices()[i];
  }
  // The elimination tree of the postordered matrix is the AMD-ordered one's, relabelled (a
  // postorder is a topological order of the tree: it keeps every ancestor after its descendants).
  std::vector<int> parent(n);
  {
    const std::vector<int> parent0 = sn_elimination_tree(sn_permuted_triangle(A, perm_, true));
    const std::vector<int> order = sn_postorder(parent0);
    std::vector<int> q(n);
    for (int k = 0; k < n; ++k) q[order[k]] = k;
    for (int i = 0; i < n; ++i) perm_[i] = q[perm_[i]];
    for (int j = 0; j < n; ++j) parent[q[j]] = parent0[j] < 0 ? -1 : q[parent0[j]];
  }
  const SnSparse C = sn_permuted_triangle(A, perm_, false);
  if (!progress.update("factor: analysis", 0.05)) return cancelled_status("factor");  // analysis: 0..0.1

  // ---- column counts of L (off-diagonal) on the postordered tree (the identity is its postorder).
  const std::vector<int> cc = sn_column_counts(C, parent);
  std::vector<int> mark(n, -1), nchild(n, 0);
  for (int k = 0; k < n; ++k)
    if (parent[k] != -1) ++nchild[parent[k]];

  // ---- fundamental supernodes, then relaxed amalgamation of a child into the next supernode.
  std::vector<int> fundamental = {0};
  for (int j = 1; j < n; ++j)
    if (!(parent[j - 1] == j && cc[j - 1] == cc[j] + 1 && nchild[j] == 1)) fundamental.push_back(j);
  fundamental.push_back(n);
  std::vector<long> col_nnz_prefix(n + 1, 0);
  for (int j = 0; j < n; ++j) col_nnz_prefix[j + 1] = col_nnz_prefix[j] + cc[j] + 1;
  int gf = fundamental[0], gl = fundamental[1];
  for (size_t s = 1; s + 1 < fundamental.size(); ++s) {
    const int pf = fundamental[s], pl = fundamental[s + 1];
    bool merged = false;
    if (parent[gl - 1] == pf) {
      const long ncols = pl - gf, below = cc[pl - 1];
      const double dense = 0.5 * ncols * (ncols + 1) + static_cast<double>(ncols) * below;
      const double actual = static_cast<double>(col_nnz_prefix[pl] - col_nnz_prefix[gf]);
      if (sn_relax_merge(static_cast<int>(ncols), (dense - actual) / dense)) {
        gl = pl;
        merged = true;
      }
    }
    if (!merged) {
      start_.push_back(gl);
      gf = pf;
      gl = pl;
    }
  }
  start_.push_back(n);
  const int ns = static_cast<int>(start_.size()) - 1;
  std::vector<int> sn_of(n);
  for (int s = 0; s < ns; ++s)
    for (int j = start_[s]; j < start_[s + 1]; ++j) sn_of[j] = s;
  std::vector<std::vector<int>> children(ns);
  for (int s = 0; s < ns; ++s) {
    const int p = parent[start_[s + 1] - 1];
    if (p != -1) children[sn_of[p]].push_back(s);
  }

  // ---- row structure below each supernode's diagonal block (children before parents).
  std::fill(mark.begin(), mark.end(), -1);
  std::vector<int> list;
  double total_flops = 0;
  for (int s = 0; s < ns; ++s) {
    const int f = start_[s], l = start_[s + 1];
    list.clear();
    for (int j = f; j < l; ++j)
      for (SnSparse::InnerIterator it(C, j); it; ++it) {
        const int i = static_cast<int>(it.row());
        if (i >= l && mark[i] != s) {
          mark[i] = s;
          list.push_back(i);
        }
      }
    for (int c : children[s])
      for (int k = rows_ptr_[c]; k < rows_ptr_[c + 1]; ++k) {
        const int i = rows_[k];
        if (i >= l && mark[i] != s) {
          mark[i] = s;
          list.push_back(i);
        }
      }
    std::sort(list.begin(), list.end());
    rows_.insert(rows_.end(), list.begin(), list.end());
    rows_ptr_.push_back(static_cast<int>(rows_.size()));
    const long ncols = l - f, m = ncols + static_cast<long>(list.size());
    value_ptr_.push_back(value_ptr_.back() + m * ncols);
    total_flops += static_cast<double>(ncols) * m * m;
  }
  values_size_ = value_ptr_.back();
  values_.reset(new double[static_cast<size_t>(values_size_)]);
  if (!progress.update("factor: analysis", 0.1)) return cancelled_status("factor");

  // ---- numeric multifrontal factorization in sn_postorder. Each supernode's update matrix waits
  // in its own slot until the parent assembles it (children in reverse order, as a stack would
  // pop them: the sums, and so the factor, do not depend on which thread did what).
  // (Uninitialised storage: only the lower triangle is written and read.)
  std::vector<std::unique_ptr<double[]>> updates(ns);
  struct Scratch {
    std::vector<int> relpos;
    std::vector<double> front;
    std::vector<double> pack;  // wasm rank update's row panels
    std::vector<int> rel;      // a child's rows in the front
    std::vector<int> run;      // lengths of their runs of consecutive front rows
  };
  auto factor_supernode = [&](int s, Scratch& w) -> Status {
    const int f = start_[s], l = start_[s + 1], ncols = l - f;
    const int nr = rows_ptr_[s + 1] - rows_ptr_[s], m = ncols + nr;
    const int* R = rows_.data() + rows_ptr_[s];
    for (int k = 0; k < ncols; ++k) w.relpos[f + k] = k;
    for (int k = 0; k < nr; ++k) w.relpos[R[k]] = ncols + k;
    // Only the lower triangle of the front is ever read (assembly, LLT, the rank update and the
    // copies below), so only it is cleared.
    if (w.front.size() < static_cast<size_t>(m) * m) w.front.resize(static_cast<size_t>(m) * m);
    for (int j = 0; j < m; ++j)
      std::fill(w.front.begin() + static_cast<long>(j) * m + j, w.front.begin() + static_cast<long>(j + 1) * m, 0.0);
    Eigen::Map<Eigen::MatrixXd> Fm(w.front.data(), m, m);
    for (int j = f; j < l; ++j)
      for (SnSparse::InnerIterator it(C, j); it; ++it) Fm(w.relpos[it.row()], j - f) += it.value();
    // Extend-add of the children's update matrices.
    for (size_t c = children[s].size(); c-- > 0;) {
      const int child = children[s][c];
      const int cn = rows_ptr_[child + 1] - rows_ptr_[child];
      const int* CR = rows_.data() + rows_ptr_[child];
      const double* Uc = updates[child].get();
      w.rel.resize(cn);
      w.run.resize(cn);
      for (int a = 0; a < cn; ++a) w.rel[a] = w.relpos[CR[a]];
      // run[a]: how many of the child's rows from a on land on consecutive rows of the front (the
      // usual case: a child's rows are mostly its parent's, in order), so that the scatter is a
      // plain vector add along each run. The same additions in the same order as one at a time.
      const int* rel = w.rel.data();
      int* run = w.run.data();
      for (int a = cn - 1; a >= 0; --a) run[a] = a + 1 < cn && rel[a + 1] == rel[a] + 1 ? run[a + 1] + 1 : 1;
      for (int b = 0; b < cn; ++b) {
        double* col = w.front.data() + static_cast<size_t>(rel[b]) * m;
        const double* u = Uc + static_cast<size_t>(b) * cn;
        for (int a = b; a < cn;) {
          double* dst = col + rel[a];
          const double* src = u + a;
          const int len = run[a];
          for (int k = 0; k < len; ++k) dst[k] += src[k];
          a += len;
        }
      }
      updates[child].reset();
    }
    // Dense partial factorization: F11 = L11 L11ᵀ, L21 = F21 L11⁻ᵀ, update F22 −= L21 L21ᵀ.
    auto F11 = Fm.topLeftCorner(ncols, ncols);
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(F11);
    if (llt.info() != Eigen::Success)
      return Status::error(StatusCode::FactorizationFailed,
                           "system matrix is singular or not positive definite (supernode at column " +
                               std::to_string(f) + ")");
    if (nr > 0) {
      auto F21 = Fm.bottomLeftCorner(nr, ncols);
      F11.triangularView<Eigen::Lower>().transpose().solveInPlace<Eigen::OnTheRight>(F21);
      auto F22 = Fm.bottomRightCorner(nr, nr);
#if defined(__wasm_simd128__)
      sn_rank_update_lower_simd(F22.data(), m, F21.data(), m, nr, ncols, w.pack);
#else
      F22.selfadjointView<Eigen::Lower>().rankUpdate(F21, -1.0);
#endif
      updates[s].reset(new double[static_cast<size_t>(nr) * nr]);
      Eigen::Map<Eigen::MatrixXd> Us(updates[s].get(), nr, nr);
      for (int b = 0; b < nr; ++b) Us.col(b).tail(nr - b) = F22.col(b).tail(nr - b);
    }
    Eigen::Map<Eigen::MatrixXd> Ls(values_.get() + value_ptr_[s], m, ncols);
    for (int k = 0; k < ncols; ++k) {
      Ls.col(k).head(k).setZero();  // the diagonal block's strict upper triangle
      Ls.col(k).tail(m - k) = Fm.col(k).tail(m - k);
    }
    for (int k = 0; k < ncols; ++k) {
      const double d = values_[value_ptr_[s] + static_cast<long>(k) * m + k];
      if (!(d > 0) || !std::isfinite(d))
        return Status::error(StatusCode::FactorizationFailed, "system matrix is singular or not positive definite");
    }
    return Status::success();
  };
  auto flops_of = [&](int s) {
    const double ncols = start_[s + 1] - start_[s], m = ncols + rows_ptr_[s + 1] - rows_ptr_[s];
    return ncols * m * m;
  };
  double done_flops = 0, reported = 0;
  Scratch main_scratch{std::vector<int>(n, -1), {}, {}, {}, {}};
  // Supernodes the calling thread factors in order (all of them, or the top of the tree once the
  // subtrees below are done).
  std::vector<int> sequence;
  // Two threads (when the build has them, on large systems): the elimination tree is cut into
  // disjoint subtrees (the largest split into its children until none holds 45 % of the work;
  // their postorder ranges are contiguous) shared out by work between this thread and a second
  // one; the supernodes above them follow here. Measured on the 48k-unknown Eq. 7 system of michael3:
  // 26 % of the flops above the cut, 37 / 37 % below.
  // (The single-threaded wasm build always takes the sequential path.)
  bool split = false;
#if MM_HAS_THREADS
  if (max_threads() > 1 && total_flops >= parallel_min_flops) {
    split = true;
    std::vector<int> snp(ns, -1), first(ns);
    std::vector<double> sub(ns, 0.0);
    for (int s = 0; s < ns; ++s) {
      first[s] = s;
      for (int c : children[s]) snp[c] = s, first[s] = std::min(first[s], first[c]);
      sub[s] += flops_of(s);
      for (int c : children[s]) sub[s] += sub[c];
    }
    std::vector<int> open;
    for (int s = 0; s < ns; ++s)
      if (snp[s] < 0) open.push_back(s);
    std::vector<char> top(ns, 0);
    for (int it = 0; it < 64 && !open.empty(); ++it) {
      const auto big = std::max_element(open.begin(), open.end(), [&](int x, int y) { return sub[x] < sub[y]; });
      if (sub[*big] < 0.45 * total_flops) break;
      const int x = *big;
      open.erase(big);
      top[x] = 1;
      open.insert(open.end(), children[x].begin(), children[x].end());
    }
    std::stable_sort(open.begin(), open.end(), [&](int x, int y) { return sub[x] > sub[y]; });
    std::vector<int> bins[2];
    double load[2] = {0, 0};
    std::vector<int> bin_of(ns, -1);
    for (int x : open) {
      const int k = load[0] <= load[1] ? 0 : 1;
      load[k] += sub[x];
      bin_of[x] = k;
      for (int t = first[x]; t <= x; ++t) bins[k].push_back(t);
    }
    for (int k = 0; k < 2; ++k) std::sort(bins[k].begin(), bins[k].end());
    top_ = top;
    first_ = first;
    for (int x : open) bins_[bin_of[x]].push_back(x);
    for (int k = 0; k < 2; ++k) std::sort(bins_[k].begin(), bins_[k].end());
    std::atomic<bool> stop{false};
    Status worker_status = Status::success();
    auto run = [&](const std::vector<int>& list, Scratch& w, Status* st) {
      for (int t : list) {
        if (stop.load(std::memory_order_relaxed)) return;
        if (Status e = factor_supernode(t, w); !e.ok()) {
          *st = e;
          stop = true;
          return;
        }
      }
    };
    Scratch worker_scratch{std::vector<int>(n, -1), {}, {}, {}, {}};
    Status main_status = Status::success();
    Task worker([&] { run(bins[1], worker_scratch, &worker_status); });
    run(bins[0], main_scratch, &main_status);
    worker.wait();
    if (!main_status.ok()) return main_status;
    if (!worker_status.ok()) return worker_status;
    done_flops = load[0] + load[1];
    for (int s = 0; s < ns; ++s)
      if (top[s]) sequence.push_back(s);
  }
#endif
  if (!split) {
    sequence.resize(ns);
    for (int s = 0; s < ns; ++s) sequence[s] = s;
  }
  for (int s : sequence) {
    if (Status e = factor_supernode(s, main_scratch); !e.ok()) return e;
    done_flops += flops_of(s);
    if (done_flops - reported > 0.02 * total_flops) {
      reported = done_flops;
      if (!progress.update("factor", 0.1 + 0.9 * done_flops / total_flops)) return cancelled_status("factor");
    }
  }
  // Relative pivot check, as SpdSolver does: a tiny pivot means a numerically singular matrix.
  double max_d = 0, min_d = std::numeric_limits<double>::infinity();
  for (int s = 0; s < ns; ++s) {
    const int ncols = start_[s + 1] - start_[s], m = ncols + rows_ptr_[s + 1] - rows_ptr_[s];
    for (int k = 0; k < ncols; ++k) {
      const double d = values_[value_ptr_[s] + static_cast<long>(k) * m + k];
      max_d = std::max(max_d, d * d);
      min_d = std::min(min_d, d * d);
    }
  }
  if (!(min_d > 1e-14 * max_d))
    return Status::error(StatusCode::FactorizationFailed, "system matrix is numerically singular");
  factored_ = true;
  return Status::success();
}

void SupernodalCholesky::solve_in_place(Eigen::MatrixXd& B) const {
  const int k = static_cast<int>(B.cols());
  if (k == 0 || n_ == 0) return;
  // Row-major work arrays: the gathers and scatters touch whole rows (k values each), which are
  // then contiguous instead of k cache lines apart.
  RowMatrix Y(n_, k);
  for (int i = 0; i < n_; ++i) Y.row(perm_[i]) = B.row(i);
#if MM_HAS_THREADS
  if (!top_.empty() && max_threads() > 1) {
    solve_split(Y);
    for (int i = 0; i < n_; ++i) B.row(i) = Y.row(perm_[i]);
    return;
  }
#endif
  const int ns = static_cast<int>(start_.size()) - 1;
  RowMatrix tmp;
  for (int s = 0; s < ns; ++s) forward_supernode(s, Y, tmp, 0, nullptr);
  for (int s = ns - 1; s >= 0; --s) backward_supernode(s, Y, tmp);
  for (int i = 0; i < n_; ++i) B.row(i) = Y.row(perm_[i]);
}

// Right-hand sides up to which the solves use the loops below instead of Eigen's triangular
// solve and GEMM (which pack their operands first). Measured on michael3's Eq. 7 factor (48k
// unknowns, 14M stored entries), one thread, one solve: 1 / 3 / 4 / 8 right-hand sides 24 / 33 /
// 34 / 48 ms, against 46 / 55 / 55 / 62 ms with per-column loops of run-time length and Eigen's
// triangular solves; reading the factor twice at this machine's ~10 GB/s takes ~22 ms.
constexpr long kSkinny = 8;

namespace supernodal_detail {

// Calls f(std::integral_constant<int, K>) for k = K in 1..kSkinny: the panel loops below get a
// compile-time row length, so they unroll and vectorise over the right-hand sides.
template <class F>
void sn_skinny(int k, F&& f) {
  switch (k) {
    case 1: f(std::integral_constant<int, 1>()); break;
    case 2: f(std::integral_constant<int, 2>()); break;
    case 3: f(std::integral_constant<int, 3>()); break;
    case 4: f(std::integral_constant<int, 4>()); break;
    case 5: f(std::integral_constant<int, 5>()); break;
    case 6: f(std::integral_constant<int, 6>()); break;
    case 7: f(std::integral_constant<int, 7>()); break;
    default: f(std::integral_constant<int, 8>()); break;
  }
}
static_assert(kSkinny == 8, "sn_skinny dispatches 1..8 right-hand sides");

// Columns per pass of the panel loops: enough to load and store each row of t once per several
// columns, few enough that the K·B sums stay in registers.
template <int K>
constexpr int sn_panel_block() { return K <= 4 ? 8 : 4; }

#if defined(__wasm_simd128__)
// A row of K right-hand sides in wasm: ⌈K/2⌉ f64x2 lanes (for odd K the last one holds one value,
// loaded and stored as a single double). Eigen 3.4 has no wasm packets, so its fixed-size arrays
// ran these loops one double at a time. Element-wise, each entry rounds as the scalar code would
// (a product, then a sum or difference; no fused operations).
template <int K>
struct SnRow {
  static constexpr int P = (K + 1) / 2;
  v128_t v[P];
  void setZero() {
    for (v128_t& x : v) x = wasm_f64x2_splat(0.0);
  }
};
template <int K>
struct SnScaled {
  double s;
  const SnRow<K>& y;
};
template <int K>
SnScaled<K> operator*(double s, const SnRow<K>& y) {
  return {s, y};
}
template <int K>
SnRow<K> sn_load(const double* p) {
  SnRow<K> r;
  for (int i = 0; i < K / 2; ++i) r.v[i] = wasm_v128_load(p + 2 * i);
  if constexpr (K % 2 == 1) r.v[K / 2] = wasm_v128_load64_zero(p + K - 1);
  return r;
}
template <int K>
void sn_store(double* p, const SnRow<K>& r) {
  for (int i = 0; i < K / 2; ++i) wasm_v128_store(p + 2 * i, r.v[i]);
  if constexpr (K % 2 == 1) wasm_v128_store64_lane(p + K - 1, r.v[K / 2], 0);
}
template <int K>
SnRow<K>& operator+=(SnRow<K>& r, const SnScaled<K>& a) {
  const v128_t s = wasm_f64x2_splat(a.s);
  for (int i = 0; i < SnRow<K>::P; ++i) r.v[i] = wasm_f64x2_add(r.v[i], wasm_f64x2_mul(s, a.y.v[i]));
  return r;
}
template <int K>
SnRow<K>& operator-=(SnRow<K>& r, const SnScaled<K>& a) {
  const v128_t s = wasm_f64x2_splat(a.s);
  for (int i = 0; i < SnRow<K>::P; ++i) r.v[i] = wasm_f64x2_sub(r.v[i], wasm_f64x2_mul(s, a.y.v[i]));
  return r;
}
template <int K>
SnRow<K>& operator-=(SnRow<K>& r, const SnRow<K>& a) {
  for (int i = 0; i < SnRow<K>::P; ++i) r.v[i] = wasm_f64x2_sub(r.v[i], a.v[i]);
  return r;
}
template <int K>
SnRow<K>& operator/=(SnRow<K>& r, double d) {
  const v128_t s = wasm_f64x2_splat(d);
  for (int i = 0; i < SnRow<K>::P; ++i) r.v[i] = wasm_f64x2_div(r.v[i], s);
  return r;
}
#else
// A row of K right-hand sides as an Eigen fixed-size array: Eigen's own packets over the row
// (the compilers' auto-vectorisers instead vectorised the loops over rows, with in-order scalar
// reductions). Element-wise, so each entry rounds as the scalar loop would.
template <int K>
using SnRow = Eigen::Array<double, K, 1>;
template <int K>
SnRow<K> sn_load(const double* p) {
  return Eigen::Map<const SnRow<K>>(p);
}
template <int K>
void sn_store(double* p, const SnRow<K>& r) {
  Eigen::Map<SnRow<K>> row(p);
  row = r;
}
#endif

// t += P y, or t −= P y with Subtract: P the nr by ncols panel (column-major, column stride
// ld), y ncols by K and t nr by K (both row-major). B columns per pass over the rows; every
// t(a, j) takes its terms in column order.
template <int K, bool Subtract>
void sn_panel_update(const double* P, long ld, int nr, int ncols, const double* y, double* t) {
  constexpr int B = sn_panel_block<K>();
  int c = 0;
  for (; c + B <= ncols; c += B) {
    const double* p = P + c * ld;
    SnRow<K> yq[B];
    for (int q = 0; q < B; ++q) yq[q] = sn_load<K>(y + static_cast<long>(c + q) * K);
    for (int a = 0; a < nr; ++a) {
      SnRow<K> r = sn_load<K>(t + static_cast<long>(a) * K);
      for (int q = 0; q < B; ++q) {
        if constexpr (Subtract)
          r -= p[q * ld + a] * yq[q];
        else
          r += p[q * ld + a] * yq[q];
      }
      sn_store<K>(t + static_cast<long>(a) * K, r);
    }
  }
  for (; c < ncols; ++c) {
    const double* pc = P + c * ld;
    const SnRow<K> yc = sn_load<K>(y + static_cast<long>(c) * K);
    for (int a = 0; a < nr; ++a) {
      SnRow<K> r = sn_load<K>(t + static_cast<long>(a) * K);
      if constexpr (Subtract)
        r -= pc[a] * yc;
      else
        r += pc[a] * yc;
      sn_store<K>(t + static_cast<long>(a) * K, r);
    }
  }
}

// t = P y (shapes as above).
template <int K>
void sn_panel_times(const double* P, long ld, int nr, int ncols, const double* y, double* t) {
  for (long i = 0; i < static_cast<long>(nr) * K; ++i) t[i] = 0.0;
  sn_panel_update<K, false>(P, ld, nr, ncols, y, t);
}

// y −= Pᵀ t (shapes as above): B columns' sums at once over the rows of t, each summed in row
// order.
template <int K>
void sn_panel_transpose_times(const double* P, long ld, int nr, int ncols, const double* t, double* y) {
  constexpr int B = sn_panel_block<K>();
  int c = 0;
  for (; c + B <= ncols; c += B) {
    const double* p = P + c * ld;
    SnRow<K> acc[B];
    for (int q = 0; q < B; ++q) acc[q].setZero();
    for (int a = 0; a < nr; ++a) {
      const SnRow<K> ta = sn_load<K>(t + static_cast<long>(a) * K);
      for (int q = 0; q < B; ++q) acc[q] += p[q * ld + a] * ta;
    }
    for (int q = 0; q < B; ++q) {
      SnRow<K> r = sn_load<K>(y + static_cast<long>(c + q) * K);
      r -= acc[q];
      sn_store<K>(y + static_cast<long>(c + q) * K, r);
    }
  }
  for (; c < ncols; ++c) {
    const double* pc = P + c * ld;
    SnRow<K> acc;
    acc.setZero();
    for (int a = 0; a < nr; ++a) acc += pc[a] * sn_load<K>(t + static_cast<long>(a) * K);
    SnRow<K> r = sn_load<K>(y + static_cast<long>(c) * K);
    r -= acc;
    sn_store<K>(y + static_cast<long>(c) * K, r);
  }
}

// Y := D⁻¹ Y and Y := D⁻ᵀ Y for the supernode's diagonal block D (lower, column-major, column
// stride ld) and Y ncols by K row-major, by blocks of B columns: a small triangle, then the
// rows below it by the panel loops (Eigen's blocked triangular solve packs its operands first,
// which dominates for a few right-hand sides).
template <int K>
void sn_diagonal_solve(const double* D, long ld, int ncols, double* y) {
  constexpr int B = sn_panel_block<K>();
  for (int cb = 0; cb < ncols; cb += B) {
    const int ce = std::min(cb + B, ncols);
    for (int c = cb; c < ce; ++c) {
      const double* dc = D + c * ld;
      SnRow<K> yc = sn_load<K>(y + static_cast<long>(c) * K);
      yc /= dc[c];
      sn_store<K>(y + static_cast<long>(c) * K, yc);
      for (int r = c + 1; r < ce; ++r) {
        SnRow<K> yr = sn_load<K>(y + static_cast<long>(r) * K);
        yr -= dc[r] * yc;
        sn_store<K>(y + static_cast<long>(r) * K, yr);
      }
    }
    if (ce < ncols)
      sn_panel_update<K, true>(D + cb * ld + ce, ld, ncols - ce, ce - cb, y + static_cast<long>(cb) * K,
                           y + static_cast<long>(ce) * K);
  }
}
template <int K>
void sn_diagonal_transpose_solve(const double* D, long ld, int ncols, double* y) {
  constexpr int B = sn_panel_block<K>();
  for (int cb = (ncols - 1) / B * B; cb >= 0; cb -= B) {
    const int ce = std::min(cb + B, ncols);
    if (ce < ncols)
      sn_panel_transpose_times<K>(D + cb * ld + ce, ld, ncols - ce, ce - cb, y + static_cast<long>(ce) * K,
                                  y + static_cast<long>(cb) * K);
    for (int c = ce - 1; c >= cb; --c) {
      const double* dc = D + c * ld;
      SnRow<K> yc = sn_load<K>(y + static_cast<long>(c) * K);
      for (int r = c + 1; r < ce; ++r) yc -= dc[r] * sn_load<K>(y + static_cast<long>(r) * K);
      yc /= dc[c];
      sn_store<K>(y + static_cast<long>(c) * K, yc);
    }
  }
}

}  // namespace supernodal_detail

void SupernodalCholesky::forward_supernode(int s, RowMatrix& Y, RowMatrix& tmp, int limit, SolveLog* log) const {
  const int f = start_[s], ncols = start_[s + 1] - f, nr = rows_ptr_[s + 1] - rows_ptr_[s], m = ncols + nr;
  const Eigen::Map<const Eigen::MatrixXd> L(values_.get() + value_ptr_[s], m, ncols);
  auto Ys = Y.middleRows(f, ncols);
  // A few right-hand sides (drags, refinement, the handle basis): the loops above, with the row
  // length known at compile time; Eigen's triangular solve and GEMM pack their operands first,
  // which costs as much as the products here.
  const bool skinny = Y.cols() <= kSkinny;
  if (skinny)
    sn_skinny(static_cast<int>(Y.cols()), [&](auto K) { sn_diagonal_solve<decltype(K)::value>(L.data(), m, ncols, Ys.data()); });
  else
    L.topRows(ncols).triangularView<Eigen::Lower>().solveInPlace(Ys);
  if (nr == 0) return;
  // tmp = L21 Ys
  if (skinny) {
    tmp.resize(nr, Y.cols());
    sn_skinny(static_cast<int>(Y.cols()), [&](auto K) {
      sn_panel_times<decltype(K)::value>(L.data() + ncols, m, nr, ncols, Ys.data(), tmp.data());
    });
  } else {
    tmp.noalias() = L.bottomRows(nr) * Ys;
  }
  const int* R = rows_.data() + rows_ptr_[s];
  for (int a = 0; a < nr; ++a) {
    if (log && R[a] >= limit) {
      log->rows.push_back(R[a]);
      log->values.insert(log->values.end(), tmp.row(a).data(), tmp.row(a).data() + Y.cols());
    } else {
      Y.row(R[a]) -= tmp.row(a);
    }
  }
}

void SupernodalCholesky::backward_supernode(int s, RowMatrix& Y, RowMatrix& tmp) const {
  const int f = start_[s], ncols = start_[s + 1] - f, nr = rows_ptr_[s + 1] - rows_ptr_[s], m = ncols + nr;
  const Eigen::Map<const Eigen::MatrixXd> L(values_.get() + value_ptr_[s], m, ncols);
  auto Ys = Y.middleRows(f, ncols);
  const bool skinny = Y.cols() <= kSkinny;  // as in forward_supernode
  if (nr > 0) {
    tmp.resize(nr, Y.cols());
    const int* R = rows_.data() + rows_ptr_[s];
    for (int a = 0; a < nr; ++a) tmp.row(a) = Y.row(R[a]);
    // Ys −= L21ᵀ tmp
    if (skinny) {
      sn_skinny(static_cast<int>(Y.cols()), [&](auto K) {
        sn_panel_transpose_times<decltype(K)::value>(L.data() + ncols, m, nr, ncols, tmp.data(), Ys.data());
      });
    } else {
      Ys.noalias() -= L.bottomRows(nr).transpose() * tmp;
    }
  }
  if (skinny)
    sn_skinny(static_cast<int>(Y.cols()), [&](auto K) {
      sn_diagonal_transpose_solve<decltype(K)::value>(L.data(), m, ncols, Ys.data());
    });
  else
    L.topRows(ncols).triangularView<Eigen::Lower>().transpose().solveInPlace(Ys);
}

// The solves on the factor's split. Forward: each thread runs its subtrees; an update aimed at a
// row above its subtree (an ancestor above the cut) is logged instead of applied; then, in
// postorder, the supernodes above the cut are solved and each subtree's log replayed at its
// root's place — the same subtractions in the same order as the sequential solve. Backward: the
// supernodes above the cut first (they read only their ancestors), then the subtrees on both
// threads (they read their ancestors and write their own rows).
void SupernodalCholesky::solve_split(RowMatrix& Y) const {
  const int k = static_cast<int>(Y.cols());
  const int ns = static_cast<int>(start_.size()) - 1;
  std::vector<SolveLog> logs(ns);
  const auto forward_bin = [&](int b) {
    RowMatrix tmp;
    for (int x : bins_[b])
      for (int s = first_[x]; s <= x; ++s) forward_supernode(s, Y, tmp, start_[x + 1], &logs[x]);
  };
  const auto backward_bin = [&](int b) {
    RowMatrix tmp;
    for (auto it = bins_[b].rbegin(); it != bins_[b].rend(); ++it)
      for (int s = *it; s >= first_[*it]; --s) backward_supernode(s, Y, tmp);
  };
  {
    Task second([&] { forward_bin(1); });
    forward_bin(0);
    second.wait();
  }
  std::vector<char> root(ns, 0);
  for (int b = 0; b < 2; ++b)
    for (int x : bins_[b]) root[x] = 1;
  RowMatrix tmp;
  for (int s = 0; s < ns; ++s) {
    if (root[s]) {
      const SolveLog& log = logs[s];
      for (size_t e = 0; e < log.rows.size(); ++e)
        Y.row(log.rows[e]) -= Eigen::Map<const Eigen::RowVectorXd>(log.values.data() + e * k, k);
    } else if (top_[s]) {
      forward_supernode(s, Y, tmp, 0, nullptr);
    }
  }
  for (int s = ns - 1; s >= 0; --s)
    if (top_[s]) backward_supernode(s, Y, tmp);
  Task second([&] { backward_bin(1); });
  backward_bin(0);
  second.wait();
}

Status SupernodalCholesky::solve(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const {
  if (!factored_) return Status::error(StatusCode::InvalidArgument, "solve called before a successful factor");
  if (B.rows() != n_) return Status::error(StatusCode::InvalidArgument, "right-hand side has the wrong size");
  *X = B;
  solve_in_place(*X);
  if (!X->allFinite()) return Status::error(StatusCode::NumericalError, "solve produced non-finite values");
  return Status::success();
}

}  // namespace mm
