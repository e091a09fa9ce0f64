#include "spatial/uniform_grid.h"

#include <limits>

namespace mm {

PointGrid::PointGrid(const Eigen::MatrixXd& P, int cells_along_longest) : P_(P) {
  const int n = static_cast<int>(P.rows());
  if (n == 0) return;
  double lo[3] = {P(0, 0), P(0, 1), P(0, 2)}, hi[3] = {lo[0], lo[1], lo[2]};
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], P(i, k));
      hi[k] = std::max(hi[k], P(i, k));
    }
  const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  grid_.cell = longest / static_cast<double>(cells_along_longest);
  for (int k = 0; k < 3; ++k) {
    grid_.lo[k] = lo[k];
    grid_.dims[k] = static_cast<int>(std::floor((hi[k] - lo[k]) / grid_.cell)) + 1;
  }
  // Counting sort of the points by cell.
  std::vector<size_t> cell_of(n);
  start_.assign(grid_.num_cells() + 1, 0);
  for (int i = 0; i < n; ++i) {
    cell_of[i] = grid_.index(grid_.coord(P(i, 0), 0), grid_.coord(P(i, 1), 1), grid_.coord(P(i, 2), 2));
    ++start_[cell_of[i] + 1];
  }
  for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
  ids_.resize(n);
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (int i = 0; i < n; ++i) ids_[fill[cell_of[i]]++] = i;
}

double PointGrid::nearest_sq_distance(const double p[3]) const {
  double best = std::numeric_limits<double>::infinity();
  if (ids_.empty()) return best;
  const UniformGrid& g = grid_;
  const int c[3] = {g.coord(p[0], 0), g.coord(p[1], 1), g.coord(p[2], 2)};
  const int max_ring = std::max({g.dims[0], g.dims[1], g.dims[2]});
  for (int r = 0; r <= max_ring; ++r) {
    // Rings 0..r−1 are done; a point in ring r or beyond is at least r − 1 cells away.
    const double gap = (r - 1 - 1e-3) * g.cell;
    if (gap > 0 && gap * gap >= best) break;
    for (int dz = -r; dz <= r; ++dz) {
      const int z = c[2] + dz;
      if (z < 0 || z >= g.dims[2]) continue;
      for (int dy = -r; dy <= r; ++dy) {
        const int y = c[1] + dy;
        if (y < 0 || y >= g.dims[1]) continue;
        const bool shell = std::abs(dz) == r || std::abs(dy) == r;
        for (int dx = -r; dx <= r; dx += shell || r == 0 ? 1 : 2 * r) {  // inside rows: the two ends
          const int x = c[0] + dx;
          if (x < 0 || x >= g.dims[0]) continue;
          const size_t cell = g.index(x, y, z);
          for (int s = start_[cell]; s < start_[cell + 1]; ++s) {
            const int i = ids_[s];
            const double d0 = P_(i, 0) - p[0], d1 = P_(i, 1) - p[1], d2 = P_(i, 2) - p[2];
            const double d = d0 * d0 + d1 * d1 + d2 * d2;
            if (d < best) best = d;
          }
        }
      }
    }
  }
  return best;
}

}  // namespace mm
