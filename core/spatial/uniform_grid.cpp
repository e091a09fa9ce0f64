#include "spatial/uniform_grid.h"

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

}  // namespace mm
