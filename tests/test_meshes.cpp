#include "test_meshes.h"

#include <map>
#include <vector>

namespace mm::test {

void icosphere(int level, Eigen::MatrixXd* V_out, Eigen::MatrixXi* F_out) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> V = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t},  {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : V) v.normalize();
  std::vector<Eigen::Vector3i> F = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      V.push_back((V[a] + V[b]).normalized());
      mid[key] = static_cast<int>(V.size()) - 1;
      return static_cast<int>(V.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& f : F) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    F.swap(next);
  }
  V_out->resize(V.size(), 3);
  for (size_t i = 0; i < V.size(); ++i) V_out->row(i) = V[i].transpose();
  F_out->resize(F.size(), 3);
  for (size_t i = 0; i < F.size(); ++i) F_out->row(i) = F[i].transpose();
}

void grid(int nx, int ny, Eigen::MatrixXd* V, Eigen::MatrixXi* F) {
  V->resize(nx * ny, 3);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) V->row(j * nx + i) << double(i) / (nx - 1), double(j) / (ny - 1), 0.0;
  F->resize(2 * (nx - 1) * (ny - 1), 3);
  int f = 0;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      F->row(f++) << a, b, d;
      F->row(f++) << a, d, c;
    }
}

}  // namespace mm::test
