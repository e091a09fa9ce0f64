#include "operators/operators.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "mesh/topology.h"

namespace mm {

namespace {

Eigen::Vector3d row3(const Eigen::MatrixXd& V, int i) { return V.row(i).transpose(); }

}  // namespace

SparseMatrix cotan_stiffness(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  // Assembled column by column in place (no triplets to sort): each entry sums the same terms
  // in the same order as triplets (i, j, −½cot), (j, i, −½cot), (i, i, ½cot), (j, j, ½cot) per
  // corner, face by face, would (faces ascending, corners in order), so the matrix is the same
  // bit for bit as a setFromTriplets of them. Sums start at −0 (−0 + x = x for every x).
  const int n = static_cast<int>(V.rows());
  const int nf = static_cast<int>(F.rows());
  std::vector<double> half_cot(3 * static_cast<size_t>(nf));
  std::vector<char> kept(static_cast<size_t>(nf), 0);
  for (int f = 0; f < nf; ++f) {
    const int idx[3] = {F(f, 0), F(f, 1), F(f, 2)};
    if (std::min({idx[0], idx[1], idx[2]}) < 0 || std::max({idx[0], idx[1], idx[2]}) >= n) continue;  // not a face of V
    const Eigen::Vector3d p[3] = {row3(V, idx[0]), row3(V, idx[1]), row3(V, idx[2])};
    const double dbl_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (!(dbl_area > 0) || !std::isfinite(dbl_area)) continue;
    kept[f] = 1;
    for (int c = 0; c < 3; ++c) {
      // Angle at corner c is opposite the edge (c+1, c+2): cot = (u·v) / |u×v|.
      const Eigen::Vector3d u = p[(c + 1) % 3] - p[c], v = p[(c + 2) % 3] - p[c];
      half_cot[3 * static_cast<size_t>(f) + c] = 0.5 * u.dot(v) / dbl_area;
    }
  }
  // The kept faces of each vertex, ascending (corners bucketed by their vertex, in corner order).
  const VertexBuckets corners = bucket_by_vertex(n, 3 * nf, [&](int h) { return kept[h / 3] ? F(h / 3, h % 3) : -1; });
  // Column v: v and its neighbours through kept faces (collected with a stamp, sorted), then
  // the face terms added at their rows' slots.
  std::vector<int> outer(static_cast<size_t>(n) + 1, 0), inner, stamp(static_cast<size_t>(n), -1), slot(static_cast<size_t>(n), 0);
  std::vector<double> values;
  inner.reserve(corners.items.size() + static_cast<size_t>(n));
  values.reserve(inner.capacity());
  for (int v = 0; v < n; ++v) {
    const int first = outer[v];
    for (int k = corners.start[v]; k < corners.start[v + 1]; ++k)
      for (int c = 0; c < 3; ++c) {
        const int w = F(corners.items[k] / 3, c);
        if (stamp[w] != v) {
          stamp[w] = v;
          inner.push_back(w);
        }
      }
    std::sort(inner.begin() + first, inner.end());
    outer[v + 1] = static_cast<int>(inner.size());
    values.resize(inner.size(), -0.0);
    for (int k = first; k < outer[v + 1]; ++k) slot[inner[static_cast<size_t>(k)]] = k;
    for (int k = corners.start[v]; k < corners.start[v + 1]; ++k) {
      const int f = corners.items[k] / 3;
      for (int c = 0; c < 3; ++c) {
        const int i = F(f, (c + 1) % 3), j = F(f, (c + 2) % 3);
        if (i != v && j != v) continue;
        const double h = half_cot[3 * static_cast<size_t>(f) + c];
        values[static_cast<size_t>(slot[i == v ? j : i])] += -h;
        values[static_cast<size_t>(slot[v])] += h;
      }
    }
  }
  SparseMatrix W(n, n);
  W.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), W.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), W.innerIndexPtr());
  std::copy(values.begin(), values.end(), W.valuePtr());
  return W;
}

Eigen::VectorXd mass_diagonal(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, MassType type) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(V.rows());
  for (int f = 0; f < F.rows(); ++f) {
    const int idx[3] = {F(f, 0), F(f, 1), F(f, 2)};
    const Eigen::Vector3d p[3] = {row3(V, idx[0]), row3(V, idx[1]), row3(V, idx[2])};
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (!(area > 0) || !std::isfinite(area)) continue;
    if (type == MassType::Barycentric) {
      for (int c = 0; c < 3; ++c) a[idx[c]] += area / 3.0;
      continue;
    }
    // Mixed Voronoi area (Meyer, Desbrun, Schröder, Barr 2003, Fig. 4).
    double dots[3];
    for (int c = 0; c < 3; ++c)
      dots[c] = (p[(c + 1) % 3] - p[c]).dot(p[(c + 2) % 3] - p[c]);
    const int obtuse = dots[0] < 0 ? 0 : dots[1] < 0 ? 1 : dots[2] < 0 ? 2 : -1;
    if (obtuse >= 0) {
      for (int c = 0; c < 3; ++c) a[idx[c]] += (c == obtuse ? 0.5 : 0.25) * area;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      // Edge (c, c+1) has length² l2 and opposite angle at c+2 with cot = dots / (2·area).
      const int o = (c + 2) % 3;
      const double cot_o = dots[o] / (2.0 * area);
      const double l2 = (p[(c + 1) % 3] - p[c]).squaredNorm();
      const double contrib = l2 * cot_o / 8.0;
      a[idx[c]] += contrib;
      a[idx[(c + 1) % 3]] += contrib;
    }
  }
  return a;
}

SparseMatrix mass_matrix(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, MassType type) {
  const Eigen::VectorXd a = mass_diagonal(V, F, type);
  SparseMatrix A(a.size(), a.size());
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(a.size());
  for (int i = 0; i < a.size(); ++i) t.emplace_back(i, i, a[i]);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

SparseMatrix uniform_laplacian(const Eigen::MatrixXi& F, int n) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(F.rows() * 6);
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int i = F(f, c), j = F(f, (c + 1) % 3);
      if (i == j) continue;
      t.emplace_back(i, j, 1.0);
      t.emplace_back(j, i, 1.0);
    }
  SparseMatrix adj(n, n);
  adj.setFromTriplets(t.begin(), t.end());
  // Edges shared by two faces were added twice: keep only the pattern.
  for (int k = 0; k < adj.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(adj, k); it; ++it) it.valueRef() = 1.0;
  SparseMatrix L = -adj;
  Eigen::VectorXd deg = adj * Eigen::VectorXd::Ones(n);
  for (int i = 0; i < n; ++i) L.coeffRef(i, i) += deg[i];
  L.makeCompressed();
  return L;
}

Eigen::MatrixXd face_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d n = (row3(V, F(f, 1)) - row3(V, F(f, 0))).cross(row3(V, F(f, 2)) - row3(V, F(f, 0)));
    const double len = n.norm();
    if (len > 0 && std::isfinite(len)) N.row(f) = (n / len).transpose();
  }
  return N;
}

Eigen::MatrixXd vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  return grouped_vertex_normals(V, F, F, static_cast<int>(V.rows()));
}

Eigen::MatrixXd grouped_vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXi& G,
                                       int num_groups) {
  // Row-major copies of V and of the sums: each face reads three whole points and adds into three
  // whole rows, one cache line each instead of three (the column-major matrices put x, y and z
  // of a vertex 8·#V bytes apart). At 1M vertices the loop is memory-bound: 4× faster this way.
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  const Rows P = V.leftCols<3>();
  Rows N = Rows::Zero(num_groups, 3);
  const int nv = static_cast<int>(V.rows());
  for (int f = 0; f < F.rows(); ++f) {
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (a < 0 || b < 0 || c < 0 || a >= nv || b >= nv || c >= nv) continue;
    // Unnormalised cross product = 2·area·normal: area weighting for free.
    const Eigen::RowVector3d n = (P.row(b) - P.row(a)).cross(P.row(c) - P.row(a));
    if (!n.allFinite()) continue;
    for (int k = 0; k < 3; ++k) {
      const int g = G(f, k);
      if (g >= 0 && g < num_groups) N.row(g) += n;
    }
  }
  for (int g = 0; g < num_groups; ++g) {
    const double len = N.row(g).norm();
    if (len > 0) N.row(g) /= len;
  }
  return N;
}

Eigen::VectorXd face_areas(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  Eigen::VectorXd a(F.rows());
  for (int f = 0; f < F.rows(); ++f)
    a[f] = 0.5 * (row3(V, F(f, 1)) - row3(V, F(f, 0))).cross(row3(V, F(f, 2)) - row3(V, F(f, 0))).norm();
  return a;
}

}  // namespace mm
