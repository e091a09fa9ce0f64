// Uniform grids of cubic cells for box queries, in plain scalar arithmetic (the same bits
// natively and in wasm; cage/hull_decimation takes discrete decisions on them):
//   UniformGrid  the cell geometry: origin, cell size, cells per axis; coordinates clamp to
//                the border cells, so every box maps to a (possibly clamped) range of cells.
//   PointGrid    a fixed point set bucketed once (CSR layout): box queries, nearest point.
//   BoxGrid      items inserted by bounding box (each overlapped cell lists the item); items
//                that change are inserted again and the old entries pruned lazily.
// Box arguments are any 3-vector type with operator[] (double[3], Eigen::Vector3d, ...).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace mm {

struct UniformGrid {
  double lo[3] = {0, 0, 0};  // corner of cell (0, 0, 0)
  double cell = 1;           // edge length of a cell (> 0)
  int dims[3] = {1, 1, 1};   // cells along x, y, z

  // Cell coordinate of v along axis k, clamped to [0, dims[k] − 1].
  int coord(double v, int k) const {
    return std::clamp(static_cast<int>(std::floor((v - lo[k]) / cell)), 0, dims[k] - 1);
  }
  // Linear index of cell (x, y, z), x fastest.
  size_t index(int x, int y, int z) const {
    return x + static_cast<size_t>(dims[0]) * (y + static_cast<size_t>(dims[1]) * z);
  }
  size_t num_cells() const { return static_cast<size_t>(dims[0]) * dims[1] * dims[2]; }

  // Cells overlapping the box [blo, bhi]: r0[k] ≤ cell coordinate ≤ r1[k].
  template <class Vec>
  void cell_range(const Vec& blo, const Vec& bhi, int r0[3], int r1[3]) const {
    for (int k = 0; k < 3; ++k) {
      r0[k] = coord(blo[k], k);
      r1[k] = coord(bhi[k], k);
    }
  }

  // Calls fn(cell index) for every cell overlapping [blo, bhi] (z outermost, x innermost);
  // stops and returns false as soon as fn does.
  template <class Vec, class Fn>
  bool for_each_cell(const Vec& blo, const Vec& bhi, Fn fn) const {
    int r0[3], r1[3];
    cell_range(blo, bhi, r0, r1);
    for (int z = r0[2]; z <= r1[2]; ++z)
      for (int y = r0[1]; y <= r1[1]; ++y)
        for (int x = r0[0]; x <= r1[0]; ++x)
          if (!fn(index(x, y, z))) return false;
    return true;
  }
};

// Rows of P (#P by 3) in a uniform grid over their bounding box, `cells_along_longest` cells
// along its longest side. P is referenced, not copied: it must outlive the grid.
class PointGrid {
 public:
  explicit PointGrid(const Eigen::MatrixXd& P, int cells_along_longest = 48);

  // Calls fn(i) for every row i of P inside the closed box [blo, bhi], cell by cell; stops and
  // returns false as soon as fn does.
  template <class Vec, class Fn>
  bool for_each_in_box(const Vec& blo, const Vec& bhi, Fn fn) const {
    if (ids_.empty()) return true;
    return grid_.for_each_cell(blo, bhi, [&](size_t c) {
      for (int s = start_[c]; s < start_[c + 1]; ++s) {
        const int i = ids_[s];
        const double x = P_(i, 0), y = P_(i, 1), z = P_(i, 2);
        if (x < blo[0] || y < blo[1] || z < blo[2] || x > bhi[0] || y > bhi[1] || z > bhi[2]) continue;
        if (!fn(i)) return false;
      }
      return true;
    });
  }

  // Smallest squared distance from p to a row of P (+inf for an empty grid), each candidate's
  // summed (dx² + dy²) + dz², as Eigen's row squaredNorm does: the same bits as a brute-force
  // minimum. Searches rings of cells around p's (clamped) cell until no unvisited cell can be
  // nearer.
  double nearest_sq_distance(const double p[3]) const;

  const UniformGrid& grid() const { return grid_; }

 private:
  const Eigen::MatrixXd& P_;
  UniformGrid grid_;
  std::vector<int> start_, ids_;  // cell c holds ids_[start_[c] .. start_[c + 1])
};

// Entries of type Entry filed under every cell their bounding box overlaps (grids of at most
// 65,535 cells along each axis). Each copy keeps the entry's cell range: a query reports an entry
// once, from the first cell where its range and the query's overlap (no visited set), and an
// entry can be removed from exactly the cells that hold it.
template <class Entry>
class BoxGrid {
 public:
  struct Range {
    uint16_t lo[3], hi[3];
  };

  void reset(const UniformGrid& grid) {
    grid_ = grid;
    cells_.assign(grid_.num_cells(), {});
  }
  const UniformGrid& grid() const { return grid_; }

  template <class Vec>
  Range range(const Vec& blo, const Vec& bhi) const {
    int r0[3], r1[3];
    grid_.cell_range(blo, bhi, r0, r1);
    Range r;
    for (int k = 0; k < 3; ++k) {
      r.lo[k] = static_cast<uint16_t>(r0[k]);
      r.hi[k] = static_cast<uint16_t>(r1[k]);
    }
    return r;
  }

  void insert(const Range& r, const Entry& e) {
    for_cells(r, [&](std::vector<Stored>& cell) { cell.push_back({e, r}); });
  }

  // Removes, from each cell of r, the first copy `match` accepts (cell order is not kept).
  template <class Match>
  void remove(const Range& r, Match match) {
    for_cells(r, [&](std::vector<Stored>& cell) {
      for (size_t i = 0; i < cell.size(); ++i)
        if (match(cell[i].e)) {
          cell[i] = cell.back();
          cell.pop_back();
          return;
        }
    });
  }

  // fn(entry) once for every entry filed under a cell the box overlaps; stops at the first false.
  template <class Vec, class Fn>
  bool for_each_in_box(const Vec& blo, const Vec& bhi, Fn fn) const {
    const Range q = range(blo, bhi);
    for (int z = q.lo[2]; z <= q.hi[2]; ++z)
      for (int y = q.lo[1]; y <= q.hi[1]; ++y)
        for (int x = q.lo[0]; x <= q.hi[0]; ++x)
          for (const Stored& s : cells_[grid_.index(x, y, z)]) {
            // Reported from the first cell of the overlap only.
            if (std::max(s.r.lo[0], q.lo[0]) != x || std::max(s.r.lo[1], q.lo[1]) != y ||
                std::max(s.r.lo[2], q.lo[2]) != z)
              continue;
            if (!fn(s.e)) return false;
          }
    return true;
  }

 private:
  struct Stored {
    Entry e;
    Range r;
  };
  template <class Fn>
  void for_cells(const Range& r, Fn fn) {
    for (int z = r.lo[2]; z <= r.hi[2]; ++z)
      for (int y = r.lo[1]; y <= r.hi[1]; ++y)
        for (int x = r.lo[0]; x <= r.hi[0]; ++x) fn(cells_[grid_.index(x, y, z)]);
  }

  UniformGrid grid_;
  std::vector<std::vector<Stored>> cells_;
};

}  // namespace mm
