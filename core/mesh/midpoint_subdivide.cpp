#include "mesh/midpoint_subdivide.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace mm {

Mesh midpoint_subdivide(const Mesh& m) {
  const int n = m.num_vertices();
  std::unordered_map<uint64_t, int> mid;
  mid.reserve(static_cast<size_t>(m.num_faces()) * 2);
  std::vector<Eigen::RowVector3d> extra;
  auto midpoint = [&](int a, int b) {
    const uint64_t key = (uint64_t(uint32_t(std::min(a, b))) << 32) | uint32_t(std::max(a, b));
    const auto [it, added] = mid.try_emplace(key, n + static_cast<int>(extra.size()));
    if (added) extra.push_back(0.5 * (m.V.row(a) + m.V.row(b)));
    return it->second;
  };
  Mesh out;
  out.F.resize(4 * m.F.rows(), 3);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  out.V.resize(n + static_cast<Eigen::Index>(extra.size()), 3);
  out.V.topRows(n) = m.V;
  for (size_t k = 0; k < extra.size(); ++k) out.V.row(n + static_cast<Eigen::Index>(k)) = extra[k];
  return out;
}

}  // namespace mm
