#include "cage/offset_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "cage/cage_detail.h"

namespace mm {

namespace offset_detail {

using cage_detail::Vec3;

struct Grid {
  int nx = 0, ny = 0, nz = 0;
  Vec3 origin;
  double h = 1;
  long size() const { return static_cast<long>(nx) * ny * nz; }
  long index(int i, int j, int k) const { return i + static_cast<long>(nx) * (j + static_cast<long>(ny) * k); }
};

// 1D squared distance transform of sampled function f (Felzenszwalb & Huttenlocher 2012):
// d[q] = min_p (q − p)² + f[p]. f = +inf marks "no site".
void squared_distance_1d(const std::vector<double>& f, std::vector<double>& d, std::vector<int>& v,
                         std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  const double inf = std::numeric_limits<double>::infinity();
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == inf) continue;
    while (k >= 0) {
      const int p = v[k];
      const double s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * q - 2.0 * p);
      if (s <= z[k]) {
        --k;
        continue;
      }
      break;
    }
    ++k;
    v[k] = q;
    if (k == 0) {
      z[k] = -inf;
    } else {
      const int p = v[k - 1];
      z[k] = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * q - 2.0 * p);
    }
    z[k + 1] = inf;
  }
  if (k < 0) {
    std::fill(d.begin(), d.end(), inf);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double t = q - v[j];
    d[q] = t * t + f[v[j]];
  }
}

// Squared Euclidean distance (in voxels²) from every node to the nearest node with site = 1.
std::vector<double> squared_distance_transform(const Grid& g, const std::vector<uint8_t>& site) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> D(g.size());
  for (long i = 0; i < g.size(); ++i) D[i] = site[i] ? 0.0 : inf;
  const int dims[3] = {g.nx, g.ny, g.nz};
  const int longest = std::max({g.nx, g.ny, g.nz});
  std::vector<double> f(longest), d(longest), z(longest + 1);
  std::vector<int> v(longest);
  for (int axis = 0; axis < 3; ++axis) {
    const int n = dims[axis];
    f.resize(n);
    d.resize(n);
    v.resize(n);
    z.resize(n + 1);
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int s = 0; s < dims[a2]; ++s)
      for (int r = 0; r < dims[a1]; ++r) {
        int ijk[3];
        ijk[a1] = r;
        ijk[a2] = s;
        for (int q = 0; q < n; ++q) {
          ijk[axis] = q;
          f[q] = D[g.index(ijk[0], ijk[1], ijk[2])];
        }
        squared_distance_1d(f, d, v, z);
        for (int q = 0; q < n; ++q) {
          ijk[axis] = q;
          D[g.index(ijk[0], ijk[1], ijk[2])] = d[q];
        }
      }
  }
  return D;
}

// Breadth-first fill over nodes with passable = 1 from every passable border node, through
// the given neighbour offsets. Returns reached = 1.
std::vector<uint8_t> flood_from_border(const Grid& g, const std::vector<uint8_t>& passable,
                                       const std::vector<std::array<int, 3>>& steps) {
  std::vector<uint8_t> reached(g.size(), 0);
  std::vector<long> queue;
  queue.reserve(g.size() / 4);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const bool border = i == 0 || j == 0 || k == 0 || i == g.nx - 1 || j == g.ny - 1 || k == g.nz - 1;
        const long id = g.index(i, j, k);
        if (border && passable[id]) {
          reached[id] = 1;
          queue.push_back(id);
        }
      }
  for (size_t head = 0; head < queue.size(); ++head) {
    const long id = queue[head];
    const int i = static_cast<int>(id % g.nx);
    const int j = static_cast<int>((id / g.nx) % g.ny);
    const int k = static_cast<int>(id / (static_cast<long>(g.nx) * g.ny));
    for (const auto& s : steps) {
      const int a = i + s[0], b = j + s[1], c = k + s[2];
      if (a < 0 || b < 0 || c < 0 || a >= g.nx || b >= g.ny || c >= g.nz) continue;
      const long n = g.index(a, b, c);
      if (passable[n] && !reached[n]) {
        reached[n] = 1;
        queue.push_back(n);
      }
    }
  }
  return reached;
}

}  // namespace offset_detail

OffsetSurface offset_surface(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                             const OffsetSurfaceOptions& opt, const Progress& progress) {
  using namespace offset_detail;
  OffsetSurface out;
  if (V.rows() == 0 || F.rows() == 0) {
    out.status = Status::error(StatusCode::InvalidMesh, "cannot build an offset surface of an empty mesh");
    return out;
  }
  if (!V.allFinite()) {
    out.status = Status::error(StatusCode::InvalidMesh, "mesh has non-finite coordinates");
    return out;
  }
  const Eigen::Vector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  const double longest = (hi - lo).maxCoeff();
  if (!(longest > 0)) {
    out.status = Status::error(StatusCode::InvalidMesh, "mesh has zero extent");
    return out;
  }
  if (!(opt.offset_voxels > 0) || (opt.voxel_size <= 0 && opt.resolution < 4)) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "offset surface needs offset_voxels > 0 and a resolution of at least 4 cells");
    return out;
  }
  Grid g;
  g.h = opt.voxel_size > 0 ? opt.voxel_size : longest / opt.resolution;
  const double d = opt.offset_voxels * g.h;
  // The offset surface stays two cells away from the border. Half a voxel more on the low side
  // keeps the bounding box's planes (and so the extreme vertices) off the grid planes.
  const double pad = d + 3 * g.h, low_pad = pad + 0.5 * g.h;
  g.origin = Vec3(lo.x() - low_pad, lo.y() - low_pad, lo.z() - low_pad);
  const long nx = static_cast<long>(std::ceil((hi.x() - lo.x() + pad + low_pad) / g.h)) + 1;
  const long ny = static_cast<long>(std::ceil((hi.y() - lo.y() + pad + low_pad) / g.h)) + 1;
  const long nz = static_cast<long>(std::ceil((hi.z() - lo.z() + pad + low_pad) / g.h)) + 1;
  if (nx * ny * nz > opt.max_grid_nodes) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "offset grid of " + std::to_string(nx) + "x" + std::to_string(ny) + "x" +
                                   std::to_string(nz) + " nodes is too large; lower the resolution");
    return out;
  }
  g.nx = static_cast<int>(nx);
  g.ny = static_cast<int>(ny);
  g.nz = static_cast<int>(nz);
  out.voxel_size = g.h;
  out.offset = d;

  // 1. Mark the 8 corners of the cell of every surface sample (spacing ≤ h/2, see header).
  std::vector<uint8_t> marked(g.size(), 0);
  auto mark = [&](const Vec3& p) {
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const int dim = a == 0 ? g.nx : (a == 1 ? g.ny : g.nz);
      c[a] = std::clamp(static_cast<int>(std::floor((p[a] - g.origin[a]) / g.h)), 0, dim - 2);
    }
    for (int b = 0; b < 8; ++b) marked[g.index(c[0] + (b & 1), c[1] + ((b >> 1) & 1), c[2] + ((b >> 2) & 1))] = 1;
  };
  const int nv = static_cast<int>(V.rows());
  auto vertex = [&](int i) { return Vec3(V(i, 0), V(i, 1), V(i, 2)); };
  for (int i = 0; i < nv; ++i) mark(vertex(i));
  for (int f = 0; f < F.rows(); ++f) {
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (a < 0 || b < 0 || c < 0 || a >= nv || b >= nv || c >= nv) continue;
    const Vec3 A = vertex(a), B = vertex(b), C = vertex(c);
    const double L = std::max({cage_detail::norm(B - A), cage_detail::norm(C - A), cage_detail::norm(C - B)});
    const int N = std::max(1, static_cast<int>(std::ceil(L / (0.5 * g.h))));
    if (N == 1) continue;  // the three corners (already marked) are within h/2 of every point
    for (int s = 0; s <= N; ++s)
      for (int t = 0; s + t <= N; ++t) mark(A + (double(s) / N) * (B - A) + (double(t) / N) * (C - A));
  }
  if (!progress.update("cage: voxelise", 0.2)) {
    out.status = cancelled_status("cage: voxelise");
    return out;
  }

  // 2. Exterior = unmarked nodes reachable from the border (6-connected); solid = the rest.
  const std::vector<std::array<int, 3>> six = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<uint8_t> free_node(g.size());
  for (long i = 0; i < g.size(); ++i) free_node[i] = !marked[i];
  const std::vector<uint8_t> exterior = flood_from_border(g, free_node, six);
  std::vector<uint8_t> solid(g.size());
  for (long i = 0; i < g.size(); ++i) solid[i] = !exterior[i];
  marked.clear();
  marked.shrink_to_fit();

  // 3. Distance to the solid, in voxels; field = distance − d/h (negative inside the offset).
  const std::vector<double> D2 = squared_distance_transform(g, solid);
  if (!progress.update("cage: distance transform", 0.6)) {
    out.status = cancelled_status("cage: distance transform");
    return out;
  }
  const double D = opt.offset_voxels;
  std::vector<double> field(g.size());
  for (long i = 0; i < g.size(); ++i) {
    double v = std::sqrt(D2[i]) - D;
    // Keep every node value away from 0: marching tetrahedra then yields a 2-manifold without
    // vertices sitting on nodes (which would create zero-length edges). Shifts the surface by
    // at most 1e-3 h.
    if (std::abs(v) < 1e-3) v = v < 0 ? -1e-3 : 1e-3;
    field[i] = v;
  }

  // 4. Fill pockets: outside nodes the offset closed off from the border. Connectivity is that
  // of the Kuhn tetrahedra's edges (axis, the three +/+ face diagonals, the main diagonal).
  const std::vector<std::array<int, 3>> kuhn = {
      {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 1, 0},
      {-1, -1, 0}, {1, 0, 1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, -1}, {1, 1, 1}, {-1, -1, -1}};
  std::vector<uint8_t> positive(g.size());
  for (long i = 0; i < g.size(); ++i) positive[i] = field[i] > 0;
  const std::vector<uint8_t> outside = flood_from_border(g, positive, kuhn);
  for (long i = 0; i < g.size(); ++i)
    if (positive[i] && !outside[i]) field[i] = -1e-3;

  // 5. Marching tetrahedra. Cell corners are numbered by bits (x = 1, y = 2, z = 4); the six
  // Kuhn tetrahedra follow the monotone paths 0 → 7, so neighbouring cells share face diagonals.
  std::vector<Vec3> verts;
  std::vector<std::array<int, 3>> tris;
  std::unordered_map<int64_t, int> edge_vertex;  // lookups only: output order is the scan order
  edge_vertex.reserve(1 << 16);
  const int64_t nodes = g.size();
  auto edge_point = [&](long a, long b, const Vec3& pa, const Vec3& pb) {
    const long lo_id = std::min(a, b), hi_id = std::max(a, b);
    const int64_t key = static_cast<int64_t>(lo_id) * nodes + hi_id;
    auto it = edge_vertex.find(key);
    if (it != edge_vertex.end()) return it->second;
    // Interpolate from the lower node id so the point does not depend on the visiting cell.
    const Vec3& p0 = a == lo_id ? pa : pb;
    const Vec3& p1 = a == lo_id ? pb : pa;
    const double f0 = field[lo_id], f1 = field[hi_id];
    const double t = f0 / (f0 - f1);
    verts.push_back(p0 + t * (p1 - p0));
    const int id = static_cast<int>(verts.size()) - 1;
    edge_vertex.emplace(key, id);
    return id;
  };
  static const int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k + 1 < g.nz; ++k) {
    if (k % 16 == 0 && !progress.update("cage: offset surface", 0.6 + 0.4 * k / g.nz)) {
      out.status = cancelled_status("cage: offset surface");
      return out;
    }
    for (int j = 0; j + 1 < g.ny; ++j)
      for (int i = 0; i + 1 < g.nx; ++i) {
        long id[8];
        bool any_pos = false, any_neg = false;
        for (int b = 0; b < 8; ++b) {
          id[b] = g.index(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
          (field[id[b]] > 0 ? any_pos : any_neg) = true;
        }
        if (!any_pos || !any_neg) continue;
        for (const auto& perm : kPerm) {
          const int c1 = 1 << perm[0], c2 = c1 | (1 << perm[1]);
          const int corner[4] = {0, c1, c2, 7};
          long tid[4];
          Vec3 tp[4];
          int pos[4], neg[4], np = 0, nn = 0;
          for (int t = 0; t < 4; ++t) {
            const int b = corner[t];
            tid[t] = id[b];
            tp[t] = Vec3(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));  // grid coordinates
            if (field[tid[t]] > 0) pos[np++] = t; else neg[nn++] = t;
          }
          if (np == 0 || nn == 0) continue;
          Vec3 cpos, cneg;
          for (int t = 0; t < np; ++t) cpos = cpos + tp[pos[t]];
          for (int t = 0; t < nn; ++t) cneg = cneg + tp[neg[t]];
          const Vec3 outward = (1.0 / np) * cpos - (1.0 / nn) * cneg;
          auto emit = [&](int a, int b, int c) {
            const Vec3 n = cage_detail::area_vector(verts[a], verts[b], verts[c]);
            if (cage_detail::dot(n, outward) >= 0) tris.push_back({a, b, c});
            else tris.push_back({a, c, b});
          };
          auto ep = [&](int u, int v) { return edge_point(tid[u], tid[v], tp[u], tp[v]); };
          if (np == 1 || nn == 1) {
            const int lone = np == 1 ? pos[0] : neg[0];
            int others[3], m = 0;
            for (int t = 0; t < 4; ++t)
              if (t != lone) others[m++] = t;
            emit(ep(lone, others[0]), ep(lone, others[1]), ep(lone, others[2]));
          } else {
            // Two and two: the crossing edges p0n0, p0n1, p1n1, p1n0 form a cycle.
            const int e0 = ep(pos[0], neg[0]), e1 = ep(pos[0], neg[1]);
            const int e2 = ep(pos[1], neg[1]), e3 = ep(pos[1], neg[0]);
            emit(e0, e1, e2);
            emit(e0, e2, e3);
          }
        }
      }
  }
  if (tris.empty()) {
    out.status = Status::error(StatusCode::InvalidMesh, "offset surface is empty (mesh too small for the grid)");
    return out;
  }
  out.grid_origin = Eigen::Vector3d(g.origin.x, g.origin.y, g.origin.z);
  out.V_grid.resize(static_cast<long>(verts.size()), 3);
  out.V.resize(static_cast<long>(verts.size()), 3);
  for (size_t v = 0; v < verts.size(); ++v) {
    const Vec3 p = g.origin + g.h * verts[v];
    for (int a = 0; a < 3; ++a) {
      out.V_grid(v, a) = verts[v][a];
      out.V(v, a) = p[a];
    }
  }
  out.F.resize(static_cast<long>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int c = 0; c < 3; ++c) out.F(t, c) = tris[t][c];
  progress.update("cage: offset surface", 1.0);
  return out;
}

}  // namespace mm
