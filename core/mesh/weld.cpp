#include "mesh/weld.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "mesh/mesh.h"

namespace mm {

namespace {

// Open-addressing hash map from a cell (three int32 coordinates) to a dense cell id (ids in
// insertion order); lookups only, so the result never depends on the table's layout. 16-byte
// slots with the key inside: one cache line per probe, and an uninitialised key array (the table
// is 1.5–3 slots per vertex, a load of at most 2/3 with linear probing; at 1M vertices its size
// and random accesses are the weld's cost: 32 MB of fresh memory, 64 MB at 2–4 slots).
class CellTable {
 public:
  using Key = std::array<int32_t, 3>;
  explicit CellTable(size_t expected) {
    size_t cap = 16;
    while (cap < expected + expected / 2) cap <<= 1;
    slots_.resize(cap);
    mask_ = cap - 1;
  }
  // Id of the cell, inserting it when new.
  int insert(const Key& k) {
    size_t h = hash(k) & mask_;
    while (slots_[h].id >= 0) {
      if (same(slots_[h].key, k)) return slots_[h].id;
      h = (h + 1) & mask_;
    }
    slots_[h].key = k;
    return slots_[h].id = count_++;
  }
  int find(const Key& k) const {
    size_t h = hash(k) & mask_;
    while (slots_[h].id >= 0) {
      if (same(slots_[h].key, k)) return slots_[h].id;
      h = (h + 1) & mask_;
    }
    return -1;
  }
  int size() const { return count_; }

 private:
  struct Slot {
    Slot() {}  // key left uninitialised on purpose (read only when id ≥ 0)
    Key key;
    int id = -1;
  };
  static bool same(const Key& a, const Key& b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }
  // Cell coordinates are regular (grids: multiples of one step), so every bit is mixed before the
  // low bits index the table: MurmurHash3's 64-bit finalizer.
  static size_t hash(const Key& k) {
    uint64_t x = (static_cast<uint64_t>(static_cast<uint32_t>(k[0])) << 32) ^ static_cast<uint32_t>(k[1]);
    x ^= static_cast<uint64_t>(static_cast<uint32_t>(k[2])) * 0x9E3779B97F4A7C15ULL;
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ULL;
    x ^= x >> 33;
    return static_cast<size_t>(x);
  }
  std::vector<Slot> slots_;
  size_t mask_ = 0;
  int count_ = 0;
};

}  // namespace

WeldResult weld_vertices(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const WeldOptions& opt) {
  const int n = static_cast<int>(V.rows());
  WeldResult out;
  out.to_welded.resize(n);
  double tol = 0;
  if (V.allFinite()) tol = opt.tolerance * bounding_box_diagonal(V);
  if (!std::isfinite(tol)) tol = 0;  // the diagonal overflowed (coordinates near 1e300): exact duplicates only

  // Contract (unchanged from the x-sweep this replaces): vertices a, b are merged, transitively,
  // when |x_a − x_b| ≤ tol and |v_a − v_b|² ≤ tol² as computed in doubles (tol = 0: identical
  // coordinates, −0 = +0); non-finite vertices never merge; union-find whose root is always the
  // smallest index of its group, so numbering follows first occurrence and does not depend on
  // the order in which pairs are found. Pairs are found through a spatial hash in linear time,
  // whatever the number of vertices sharing a coordinate (grids, CAD and voxel meshes):
  //  - cells of size c ≥ 2·tol, so a partner is at most one cell away per axis, and only on a
  //    side the vertex is within tol of. c is as large as a quarter of the typical vertex spacing
  //    allows (up to 1024·tol): most vertices then lie far from every cell side and need no
  //    lookup besides their own cell. The grid starts half a cell below the bounding box, so
  //    flat meshes lying in a bounding plane are not all at a cell side;
  //  - tol = 0: identical positions share a cell; only the cell itself is searched.
  std::vector<int> rep(n);
  std::iota(rep.begin(), rep.end(), 0);
  auto find = [&rep](int x) {
    while (rep[x] != x) x = rep[x] = rep[rep[x]];
    return x;
  };
  auto unite = [&](int a, int b) {
    const int ra = find(a), rb = find(b);
    if (ra != rb) rep[std::max(ra, rb)] = std::min(ra, rb);
  };
  std::vector<char> finite(n);
  Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int v = 0; v < n; ++v) {
    finite[v] = V.row(v).allFinite();
    if (!finite[v]) continue;
    lo = lo.min(V.row(v).transpose().array());
    hi = hi.max(V.row(v).transpose().array());
  }
  const double extent = n > 0 && (hi >= lo).all() ? (hi - lo).maxCoeff() : 0.0;
  const double spacing = std::sqrt(3.0) * extent / std::sqrt(static_cast<double>(std::max(n, 1)));
  // 1e-9·extent keeps cell coordinates below ~1e9 (int32) whatever the tolerance: a larger cell
  // only adds candidates.
  double c = std::max(tol > 0 ? std::min(1024 * tol, 0.25 * spacing) : 0.25 * spacing, 1e-9 * extent);
  c = std::max(c, 2 * tol);
  if (!(c > 0)) c = 1.0;  // all finite vertices coincide (or none): one cell
  const Eigen::Array3d origin = lo - 0.5 * c;
  auto cell_key = [&](int v, Eigen::Array3d* frac) {
    CellTable::Key k;
    for (int a = 0; a < 3; ++a) {
      const double q = (V(v, a) - origin[a]) / c;
      if (!(std::abs(q) < 2e9)) {  // the extent overflowed (coordinates near ±1e308): one clamped
        k[a] = q > 0 ? 2000000000 : q < 0 ? -2000000000 : 0;  // cell per side, candidates are
        (*frac)[a] = 0.5;                                     // still checked by distance
        continue;
      }
      const double f = std::floor(q);
      k[a] = static_cast<int32_t>(f);
      (*frac)[a] = q - f;
    }
    return k;
  };
  CellTable table(static_cast<size_t>(n));
  std::vector<int> cell(n, -1);
  {
    Eigen::Array3d unused;
    for (int v = 0; v < n; ++v)
      if (finite[v]) cell[v] = table.insert(cell_key(v, &unused));
  }
  // Vertices per cell, ascending (CSR).
  const int cells = table.size();
  std::vector<int> start(cells + 1, 0), members(n);
  for (int v = 0; v < n; ++v)
    if (cell[v] >= 0) ++start[cell[v] + 1];
  for (int k = 0; k < cells; ++k) start[k + 1] += start[k];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int v = 0; v < n; ++v)
      if (cell[v] >= 0) members[fill[cell[v]]++] = v;
  }
  const double tol2 = tol * tol;
  if (tol == 0) {
    // Identical positions: each cell's distinct positions (usually one) with their first vertex.
    std::vector<int> firsts;
    for (int k = 0; k < cells; ++k) {
      firsts.clear();
      for (int i = start[k]; i < start[k + 1]; ++i) {
        const int v = members[i];
        bool found = false;
        for (int f : firsts)
          if (V(f, 0) == V(v, 0) && V(f, 1) == V(v, 1) && V(f, 2) == V(v, 2)) {
            unite(f, v);
            found = true;
            break;
          }
        if (!found) firsts.push_back(v);
      }
    }
  } else {
    constexpr double kMargin = 1e-6;         // in cells; far above the rounding of q
    const double reach = tol / c + kMargin;  // ≤ 0.5 + margin: a partner's offset, in cells
    auto close = [&](int a, int b) {
      return std::abs(V(a, 0) - V(b, 0)) <= tol && (V.row(a) - V.row(b)).squaredNorm() <= tol2;
    };
    for (int a = 0; a < n; ++a) {
      if (cell[a] < 0) continue;
      for (int i = start[cell[a]]; i < start[cell[a] + 1]; ++i)
        if (members[i] > a && close(a, members[i])) unite(a, members[i]);
      Eigen::Array3d frac;  // recomputed rather than stored (24 bytes a vertex: 24 MB at 1M)
      const CellTable::Key k = cell_key(a, &frac);
      int lo_d[3], hi_d[3];
      bool near_side = false;
      for (int ax = 0; ax < 3; ++ax) {
        lo_d[ax] = frac[ax] <= reach ? -1 : 0;
        hi_d[ax] = frac[ax] >= 1 - reach ? 1 : 0;
        near_side = near_side || lo_d[ax] || hi_d[ax];
      }
      if (!near_side) continue;
      for (int dx = lo_d[0]; dx <= hi_d[0]; ++dx)
        for (int dy = lo_d[1]; dy <= hi_d[1]; ++dy)
          for (int dz = lo_d[2]; dz <= hi_d[2]; ++dz) {
            if ((dx | dy | dz) == 0) continue;
            const int id = table.find({k[0] + dx, k[1] + dy, k[2] + dz});
            if (id < 0) continue;
            for (int i = start[id]; i < start[id + 1]; ++i)
              if (members[i] > a && close(a, members[i])) unite(a, members[i]);
          }
    }
  }
  for (int v = 0; v < n; ++v) rep[v] = find(v);
  std::vector<int> id(n, -1);
  int count = 0;
  for (int v = 0; v < n; ++v) {
    if (id[rep[v]] < 0) id[rep[v]] = count++;
    out.to_welded[v] = id[rep[v]];
  }
  out.V.resize(count, 3);
  std::vector<char> placed(count, 0);
  for (int v = 0; v < n; ++v) {
    const int w = out.to_welded[v];
    if (!placed[w]) {
      out.V.row(w) = V.row(v);
      placed[w] = 1;
    }
  }
  out.F.resize(F.rows(), 3);
  out.face_map.resize(F.rows());
  int rows = 0;
  for (int f = 0; f < F.rows(); ++f) {
    Eigen::Vector3i t;
    bool in_range = true;
    for (int c = 0; c < 3; ++c) {
      const int v = F(f, c);
      if (v < 0 || v >= n) { in_range = false; break; }
      t[c] = out.to_welded[v];
    }
    if (!in_range) continue;
    if (opt.drop_degenerate_faces && (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])) continue;
    out.F.row(rows) = t.transpose();
    out.face_map[rows++] = f;
  }
  out.F.conservativeResize(rows, 3);
  out.face_map.conservativeResize(rows);
  return out;
}

Eigen::MatrixXd unweld(const Eigen::MatrixXd& welded_values, const Eigen::VectorXi& to_welded) {
  Eigen::MatrixXd out(to_welded.size(), welded_values.cols());
  for (int v = 0; v < to_welded.size(); ++v) out.row(v) = welded_values.row(to_welded[v]);
  return out;
}

}  // namespace mm
