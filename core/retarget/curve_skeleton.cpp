#include "retarget/curve_skeleton.h"

#include "common/threads.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <tuple>

#include "mesh/topology.h"
#include "mesh/weld.h"

namespace mm {

namespace curve_skeleton_detail {

// The 26 neighbour offsets and their lengths, in a fixed order (determinism).
struct CsNeighbours {
  int d[26][3];
  double w[26];
  CsNeighbours() {
    int k = 0;
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
          if (!x && !y && !z) continue;
          d[k][0] = x, d[k][1] = y, d[k][2] = z;
          w[k] = std::sqrt(double(x * x + y * y + z * z));
          ++k;
        }
  }
};
const CsNeighbours& cs_neighbours() {
  static const CsNeighbours n;
  return n;
}

struct CsGrid {
  int nx, ny, nz;
  size_t idx(int x, int y, int z) const { return x + size_t(nx) * (y + size_t(ny) * z); }
  void xyz(size_t i, int* x, int* y, int* z) const {
    *x = int(i % nx);
    *y = int((i / nx) % ny);
    *z = int(i / (size_t(nx) * ny));
  }
  bool in(int x, int y, int z) const { return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz; }
  size_t size() const { return size_t(nx) * ny * nz; }
};

// Calls visit(j, k) for each cell j = i + d[k] inside g, k0 ≤ k < k1 (d: unit steps); visit returns
// false to stop.
template <class Visit>
void cs_for_offsets(const CsGrid& g, size_t i, const int (*d)[3], int k0, int k1, Visit&& visit) {
  int x, y, z;
  g.xyz(i, &x, &y, &z);
  if (x > 0 && y > 0 && z > 0 && x + 1 < g.nx && y + 1 < g.ny && z + 1 < g.nz) {
    // Away from the border every neighbour is inside: index offsets, no checks.
    const ptrdiff_t sy = g.nx, sz = ptrdiff_t(g.nx) * g.ny;
    for (int k = k0; k < k1; ++k)
      if (!visit(size_t(ptrdiff_t(i) + d[k][0] + sy * d[k][1] + sz * d[k][2]), k)) return;
    return;
  }
  for (int k = k0; k < k1; ++k) {
    const int a = x + d[k][0], b = y + d[k][1], c = z + d[k][2];
    if (g.in(a, b, c) && !visit(g.idx(a, b, c), k)) return;
  }
}

// Calls visit(j, k) for each neighbour j of cell i inside g, neighbours k0 ≤ k < k1 in the order
// of cs_neighbours(); visit returns false to stop.
template <class Visit>
void cs_for_neighbours(const CsGrid& g, size_t i, Visit&& visit, int k0 = 0, int k1 = 26) {
  cs_for_offsets(g, i, cs_neighbours().d, k0, k1, visit);
}

// Steps the geodesic and the bands may not take: between cells owned by two parts whose contact
// was cut (step 2b). Empty = none.
struct CsCuts {
  std::vector<int> own;      // per cell: owning part, -1 for none
  std::vector<uint8_t> cut;  // np × np
  int np = 0;
  bool blocked(size_t i, size_t j) const {
    if (own.empty()) return false;
    const int a = own[i], b = own[j];
    return a >= 0 && b >= 0 && cut[size_t(a) * np + b];
  }
};

// Dijkstra inside the solid (26-neighbourhood, weights 1, √2, √3) from `sources` (their *dist
// already 0), never stepping where `cuts` block. Cells are settled in order of distance;
// settle(i) returning true ends the search and returns true. Nothing beyond `limit` is settled.
// *dist is lowered; cells first reached are appended to *touched when it is given.
template <class Settle>
bool cs_dijkstra(const CsGrid& g, const std::vector<uint8_t>& solid, const CsCuts& cuts, const std::vector<size_t>& sources,
                 double limit, std::vector<double>* dist, std::vector<size_t>* touched, Settle&& settle) {
  const auto& N = cs_neighbours();
  using Item = std::pair<double, size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> pq;
  for (size_t i : sources) pq.push({0, i});
  while (!pq.empty()) {
    const double d = pq.top().first;
    const size_t i = pq.top().second;
    pq.pop();
    if (d > (*dist)[i]) continue;
    if (d > limit) break;
    if (settle(i)) return true;
    cs_for_neighbours(g, i, [&](size_t j, int k) {
      if (!solid[j] || cuts.blocked(i, j)) return true;
      const double nd = d + N.w[k];
      if (nd < (*dist)[j]) {
        if (touched && std::isinf((*dist)[j])) touched->push_back(j);
        (*dist)[j] = nd, pq.push({nd, j});
      }
      return true;
    });
  }
  return false;
}

// Cells within k steps (26-neighbourhood) of a cell with mask == from_value: 1, else 0. Breadth-
// first layers of the 26-neighbourhood on an unobstructed box are the Chebyshev distance, so this
// is the dilation by a (2k+1)³ cube, done as three 1-D passes of a sliding window (one counter per
// line): linear in the grid, and the same cells as the breadth-first search it replaces (which
// took 18 % of the joints bench).
std::vector<uint8_t> cs_dilate(const CsGrid& g, const std::vector<uint8_t>& mask, uint8_t from_value, int k) {
  std::vector<uint8_t> a(g.size()), b(g.size());
  for (size_t i = 0; i < g.size(); ++i) a[i] = mask[i] == from_value;
  if (k <= 0) return a;
  const int dims[3] = {g.nx, g.ny, g.nz};
  const size_t stride[3] = {1, size_t(g.nx), size_t(g.nx) * g.ny};
  for (int axis = 0; axis < 3; ++axis) {
    const int n = dims[axis];
    const size_t st = stride[axis];
    const int o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
    // Lines are independent: blocks of planes on the task threads (≥ 256k cells a block).
    const long plane = long(dims[o1]) * n;
    parallel_blocks(dims[o2], std::max(1L, 262144 / std::max(1L, plane)), [&](long v0, long v1) {
      for (long v = v0; v < v1; ++v)
        for (int u = 0; u < dims[o1]; ++u) {
          const size_t base = size_t(u) * stride[o1] + size_t(v) * stride[o2];
          // count = ones in [x − k, x + k] ∩ [0, n).
          int count = 0;
          for (int x = 0; x < std::min(k, n); ++x) count += a[base + x * st];
          for (int x = 0; x < n; ++x) {
            if (x + k < n) count += a[base + (x + k) * st];
            if (x - k - 1 >= 0) count -= a[base + (x - k - 1) * st];
            b[base + x * st] = count > 0;
          }
        }
    });
    a.swap(b);
  }
  return a;
}

// Two-pass chamfer distance (weights 1, √2, √3) from the empty cells, in cells.
std::vector<float> cs_chamfer_depth(const CsGrid& g, const std::vector<uint8_t>& solid) {
  const auto& N = cs_neighbours();
  const float inf = std::numeric_limits<float>::max() / 4;
  std::vector<float> d(g.size());
  for (size_t i = 0; i < g.size(); ++i) d[i] = solid[i] ? inf : 0.f;
  // Forward pass uses the 13 neighbours that precede a cell in scan order; backward the other 13.
  for (int pass = 0; pass < 2; ++pass) {
    const int k0 = pass == 0 ? 0 : 13, k1 = pass == 0 ? 13 : 26;
    for (size_t s = 0; s < g.size(); ++s) {
      const size_t i = pass == 0 ? s : g.size() - 1 - s;
      if (!solid[i]) continue;
      int x, y, z;
      g.xyz(i, &x, &y, &z);
      float best = d[i];
      for (int k = k0; k < k1; ++k) {
        const int a = x + N.d[k][0], b = y + N.d[k][1], c = z + N.d[k][2];
        const float dn = g.in(a, b, c) ? d[g.idx(a, b, c)] : 0.f;
        best = std::min(best, dn + float(N.w[k]));
      }
      d[i] = best;
    }
  }
  return d;
}

// Connected components (26-neighbourhood) of cells with label[i] == value... generalised:
// cells with key[i] >= 0 join neighbours with the same key. Returns a component id per cell (-1
// for key < 0) and the number of components; ids follow scan order.
int cs_components(const CsGrid& g, const std::vector<int>& key, std::vector<int>* comp, const CsCuts* cuts = nullptr) {
  comp->assign(g.size(), -1);
  int n = 0;
  std::vector<size_t> stack;
  for (size_t s = 0; s < g.size(); ++s) {
    if (key[s] < 0 || (*comp)[s] >= 0) continue;
    (*comp)[s] = n;
    stack.push_back(s);
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      cs_for_neighbours(g, i, [&](size_t j, int) {
        if ((*comp)[j] < 0 && key[j] == key[i] && !(cuts && cuts->blocked(i, j))) (*comp)[j] = n, stack.push_back(j);
        return true;
      });
    }
    ++n;
  }
  return n;
}


// Samples each triangle every ≤ h/3 and marks the cells the samples fall in (cell = floor((p − lo)
// / h) − off, clamped to g): every cell the triangle crosses but for grazed corners, which the
// closing seals.
void cs_rasterize(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<int>& faces, const Eigen::Vector3d& lo,
                  double h, const int off[3], const CsGrid& g, std::vector<uint8_t>* surf) {
  const int dims[3] = {g.nx, g.ny, g.nz};
  auto cell_of = [&](const Eigen::RowVector3d& p, int k) {
    return std::clamp(int(std::floor((p[k] - lo[k]) / h)) - off[k], 0, dims[k] - 1);
  };
  for (int f : faces) {
    const Eigen::RowVector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const double e = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
    const int n = std::max(1, int(std::ceil(3 * e / h)));
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Eigen::RowVector3d p = a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a);
        (*surf)[g.idx(cell_of(p, 0), cell_of(p, 1), cell_of(p, 2))] = 1;
      }
  }
}

// The solid a surface encloses on g (whose border cells must be empty): dilate the surface by
// close_holes, flood the exterior from the border (6-neighbourhood), erode back; the surface
// cells are solid too.
std::vector<uint8_t> cs_fill_solid(const CsGrid& g, const std::vector<uint8_t>& surf, int close_holes) {
  std::vector<uint8_t> wall = surf;
  if (close_holes > 0) wall = cs_dilate(g, surf, 1, close_holes);
  std::vector<uint8_t> ext(g.size(), 0);
  std::vector<size_t> stack;
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y) {
      const bool face = z == 0 || y == 0 || z == g.nz - 1 || y == g.ny - 1;
      for (int x = 0; x < g.nx; x += face || x == g.nx - 1 ? 1 : g.nx - 1) {  // whole row, or its two ends
        const size_t i = g.idx(x, y, z);
        if (!wall[i]) ext[i] = 1, stack.push_back(i);
      }
    }
  static const int d6[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  while (!stack.empty()) {
    const size_t i = stack.back();
    stack.pop_back();
    cs_for_offsets(g, i, d6, 0, 6, [&](size_t j, int) {
      if (!ext[j] && !wall[j]) ext[j] = 1, stack.push_back(j);
      return true;
    });
  }
  std::vector<uint8_t> solid(g.size(), 0);
  std::vector<uint8_t> near_ext;  // the exterior dilated by close_holes: what the closing eroded
  if (close_holes > 0) near_ext = cs_dilate(g, ext, 1, close_holes);
  for (size_t i = 0; i < g.size(); ++i) solid[i] = surf[i] || (!ext[i] && (close_holes == 0 || !near_ext[i]));
  return solid;
}

}  // namespace curve_skeleton_detail

bool VoxelSolid::contains(const Eigen::Vector3d& p) const {
  if (solid.empty()) return false;
  for (int k = 0; k < 3; ++k) {
    const double c = (p[k] - grid.lo[k]) / grid.cell;
    if (!(c >= 0 && c < grid.dims[k])) return false;
  }
  return solid[grid.index(grid.coord(p[0], 0), grid.coord(p[1], 1), grid.coord(p[2], 2))] != 0;
}

double VoxelSolid::depth_at(const Eigen::Vector3d& p) const {
  if (!contains(p)) return 0;
  return depth[grid.index(grid.coord(p[0], 0), grid.coord(p[1], 1), grid.coord(p[2], 2))] * grid.cell;
}

Eigen::Vector3d VoxelSolid::cell_center(size_t i) const {
  const size_t nx = grid.dims[0], ny = grid.dims[1];
  const double x = double(i % nx), y = double((i / nx) % ny), z = double(i / (nx * ny));
  return {grid.lo[0] + (x + 0.5) * grid.cell, grid.lo[1] + (y + 0.5) * grid.cell, grid.lo[2] + (z + 0.5) * grid.cell};
}

std::vector<std::vector<int>> CurveSkeleton::adjacency() const {
  std::vector<std::vector<int>> adj(size());
  for (int i = 0; i < size(); ++i)
    if (parent[i] >= 0) adj[i].push_back(parent[i]), adj[parent[i]].push_back(i);
  for (auto& a : adj) std::sort(a.begin(), a.end());
  return adj;
}

std::vector<int> CurveSkeleton::leaves() const {
  std::vector<int> out;
  const auto adj = adjacency();
  for (int i = 0; i < size(); ++i)
    if (adj[i].size() == 1) out.push_back(i);
  return out;
}

CurveSkeleton curve_skeleton(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const CurveSkeletonOptions& opt,
                             const Progress& progress) {
  using namespace curve_skeleton_detail;
  CurveSkeleton out;
  auto fail = [&](StatusCode c, const std::string& m) {
    out.status = Status::error(c, m);
    return out;
  };
  if (opt.resolution < 16 || opt.resolution > 512)
    return fail(StatusCode::InvalidArgument, "skeleton resolution must be in [16, 512]");
  if (!(opt.band_width >= 1.7320508 && opt.band_width <= 64))
    return fail(StatusCode::InvalidArgument, "skeleton band_width must be in [√3, 64] cells");
  if (opt.close_holes < 0 || opt.close_holes > 8) return fail(StatusCode::InvalidArgument, "close_holes must be in [0, 8]");
  if (V.rows() < 3 || F.rows() < 1 || V.cols() != 3 || F.cols() != 3)
    return fail(StatusCode::InvalidMesh, "the mesh is empty (" + std::to_string(V.rows()) + " vertices, " +
                                             std::to_string(F.rows()) + " triangles): no skeleton can be extracted");
  if (!V.allFinite()) return fail(StatusCode::InvalidMesh, "the mesh has non-finite vertex coordinates");
  if (F.minCoeff() < 0 || F.maxCoeff() >= V.rows())
    return fail(StatusCode::InvalidMesh, "the mesh has triangle indices outside [0, #V)");
  const Eigen::RowVector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  const double L = (hi - lo).maxCoeff();
  if (!(L > 0)) return fail(StatusCode::InvalidMesh, "the mesh has no extent");
  if ((hi - lo).minCoeff() < 1e-6 * L)
    return fail(StatusCode::InvalidMesh, "the mesh is flat (no volume): a curve skeleton needs a solid shape");

  // 1. Grid with a border of pad cells (the exterior flood starts there).
  const double h = L / opt.resolution;
  const int pad = 2 + opt.close_holes;
  CsGrid g;
  int dims[3];
  for (int k = 0; k < 3; ++k) dims[k] = int(std::ceil((hi[k] - lo[k]) / h)) + 1 + 2 * pad;
  g.nx = dims[0], g.ny = dims[1], g.nz = dims[2];
  VoxelSolid& vs = out.volume;
  // Centred on the bounding box, so a mesh turned by 180° about an axis (facing −z instead of +z)
  // meets the same cells mirrored.
  for (int k = 0; k < 3; ++k) {
    vs.grid.lo[k] = 0.5 * (lo[k] + hi[k]) - 0.5 * dims[k] * h;
    vs.grid.dims[k] = dims[k];
  }
  vs.grid.cell = h;
  const Eigen::Vector3d glo(vs.grid.lo[0], vs.grid.lo[1], vs.grid.lo[2]);
  const int no_offset[3] = {0, 0, 0};
  std::vector<uint8_t> surf(g.size(), 0);
  {
    // With a second thread, the second half of the triangles is marked on a grid of its own by a
    // pool task, then the two grids are joined (a cell is marked by either: the same grid).
    const int nf = int(F.rows());
    const int split = MM_HAS_THREADS && max_threads() > 1 && nf >= 32768 ? nf / 2 : nf;
    std::vector<uint8_t> surf2;
    StoppableTask second;  // after what it writes: an early return stops and waits for it
    if (split < nf) {
      surf2.assign(g.size(), 0);
      second = StoppableTask([&, split, nf](const Progress& watch) {
        std::vector<int> chunk;
        for (int f0 = split; f0 < nf && watch.update("skeleton: voxels", 0); f0 += 4096) {
          chunk.clear();
          for (int f = f0; f < std::min(f0 + 4096, nf); ++f) chunk.push_back(f);
          cs_rasterize(V, F, chunk, glo, h, no_offset, g, &surf2);
        }
      });
    }
    std::vector<int> chunk;
    for (int f0 = 0; f0 < split; f0 += 4096) {
      if (!progress.update("skeleton: voxels", 0.3 * f0 / split))
        return fail(StatusCode::Cancelled, "cancelled during skeleton: voxels");
      chunk.clear();
      for (int f = f0; f < std::min(f0 + 4096, split); ++f) chunk.push_back(f);
      cs_rasterize(V, F, chunk, glo, h, no_offset, g, &surf);
    }
    if (second.valid()) {
      second.wait();
      for (size_t i = 0; i < surf.size(); ++i) surf[i] |= surf2[i];
    }
  }
  std::vector<uint8_t>& solid = vs.solid;
  solid = cs_fill_solid(g, surf, opt.close_holes);
  if (!progress.update("skeleton: voxels", 0.4)) return fail(StatusCode::Cancelled, "cancelled during skeleton: voxels");

  // 2. Bridge separate parts to the largest one along the shortest path through empty cells.
  for (int round = 0; round < 256; ++round) {
    std::vector<int> key(g.size());
    for (size_t i = 0; i < g.size(); ++i) key[i] = solid[i] ? 0 : -1;
    std::vector<int> comp;
    const int nc = cs_components(g, key, &comp);
    if (nc == 0) return fail(StatusCode::InvalidMesh, "the mesh encloses no volume at this resolution");
    if (nc == 1) break;
    std::vector<size_t> count(nc, 0);
    for (size_t i = 0; i < g.size(); ++i)
      if (comp[i] >= 0) ++count[comp[i]];
    const int main = int(std::max_element(count.begin(), count.end()) - count.begin());
    // BFS (26-neighbourhood) from the main part through empty cells to the nearest other part.
    std::vector<int64_t> pred(g.size(), -2);
    std::deque<size_t> q;
    for (size_t i = 0; i < g.size(); ++i)
      if (comp[i] == main) pred[i] = -1, q.push_back(i);
    int64_t hit = -1;
    while (!q.empty() && hit < 0) {
      const size_t i = q.front();
      q.pop_front();
      cs_for_neighbours(g, i, [&](size_t j, int) {
        if (pred[j] != -2) return true;
        pred[j] = int64_t(i);
        if (comp[j] >= 0) hit = int64_t(j);
        else q.push_back(j);
        return hit < 0;
      });
    }
    if (hit < 0) break;
    for (int64_t i = pred[hit]; i >= 0 && comp[i] != main; i = pred[i]) solid[i] = 1;
    ++out.num_bridges;
  }
  vs.depth = cs_chamfer_depth(g, solid);
  // 2b. Parts that merely touch. A character built from separate parts (RobotExpressive: 63 once
  // welded, KayKit: 14–15) has parts that interpenetrate at its joints and parts that only touch
  // (a hanging forearm against the hip joint): the union solid then has a loop, and the Reeb graph
  // of step 4 would cut it where the geodesic fronts meet — mid-limb — so the arm hangs from the
  // hip. Each part's own solid is filled as in step 1; each solid cell gets an owner part; two
  // parts' contact is kOverlapWeight × the cells both hold plus the neighbouring cells the one and
  // the other own. A maximum spanning tree of the contacts keeps the strongest; a contact left out
  // is cut — the geodesic and the bands may not step across it — when it closes a loop around a
  // hole (see detour_exceeds), and kept where three parts meet at one joint.
  CsCuts cuts;
  {
    // Parts: connected components once vertices at the same position are merged (glTF splits
    // them at UV seams).
    WeldOptions wo;
    wo.tolerance = 0;
    wo.drop_degenerate_faces = false;
    const WeldResult welded = weld_vertices(V, F, wo);
    int nvc = 0;
    const Eigen::VectorXi vc = vertex_components(welded.F, int(welded.V.rows()), &nvc);
    std::vector<int> part_id(nvc, -1);
    std::vector<std::vector<int>> part_faces;
    for (int f = 0; f < F.rows(); ++f) {
      const int c = vc[welded.to_welded[F(f, 0)]];
      if (part_id[c] < 0) part_id[c] = int(part_faces.size()), part_faces.emplace_back();
      part_faces[part_id[c]].push_back(f);
    }
    const int np = int(part_faces.size());
    if (np >= 3 && np <= 64) {
      std::vector<uint64_t> mask(g.size(), 0);
      // Part p's own solid, marked as bit p of the cells it shares with the union.
      auto add_part = [&](int p, std::vector<uint64_t>* m) {
        Eigen::Vector3d plo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), phi = -plo;
        for (int f : part_faces[p])
          for (int k = 0; k < 3; ++k) {
            plo = plo.cwiseMin(V.row(F(f, k)).transpose());
            phi = phi.cwiseMax(V.row(F(f, k)).transpose());
          }
        int off[3], n[3];
        for (int k = 0; k < 3; ++k) {
          off[k] = std::max(0, int(std::floor((plo[k] - glo[k]) / h)) - pad);
          n[k] = std::min(dims[k] - 1, int(std::floor((phi[k] - glo[k]) / h)) + pad) - off[k] + 1;
        }
        const CsGrid sub{n[0], n[1], n[2]};
        std::vector<uint8_t> ps(sub.size(), 0);
        cs_rasterize(V, F, part_faces[p], glo, h, off, sub, &ps);
        ps = cs_fill_solid(sub, ps, opt.close_holes);
        for (size_t i = 0; i < sub.size(); ++i) {
          if (!ps[i]) continue;
          int x, y, z;
          sub.xyz(i, &x, &y, &z);
          const size_t j = g.idx(x + off[0], y + off[1], z + off[2]);
          if (solid[j]) (*m)[j] |= uint64_t(1) << p;
        }
      };
      // With a second thread, the parts holding the second half of the triangles are done on a pool
      // task into a mask of its own, joined after (the bits are the same either way).
      int split = np;
      if (MM_HAS_THREADS && max_threads() > 1 && F.rows() >= 32768) {
        long acc = 0;
        for (split = 0; split < np && 2 * acc < F.rows(); ++split) acc += long(part_faces[split].size());
      }
      std::vector<uint64_t> mask2;
      StoppableTask second;  // after what it writes: an early return stops and waits for it
      if (split < np) {
        mask2.assign(g.size(), 0);
        second = StoppableTask([&, split](const Progress& watch) {
          for (int p = split; p < np && watch.update("skeleton: parts", 0); ++p) add_part(p, &mask2);
        });
      }
      for (int p = 0; p < split; ++p) {
        if (!progress.update("skeleton: parts", 0.4 + 0.05 * p / np))
          return fail(StatusCode::Cancelled, "cancelled during skeleton: parts");
        add_part(p, &mask);
      }
      if (second.valid()) {
        second.wait();
        for (size_t i = 0; i < mask.size(); ++i) mask[i] |= mask2[i];
      }
      // Owner of each solid cell: the lowest part holding it; cells of no part (gaps the closing
      // filled, bridges) take the part that reaches them first, breadth-first in scan order.
      cuts.own.assign(g.size(), -1);
      {
        std::deque<size_t> q;
        for (size_t i = 0; i < g.size(); ++i)
          if (mask[i]) cuts.own[i] = __builtin_ctzll(mask[i]), q.push_back(i);
        while (!q.empty()) {
          const size_t i = q.front();
          q.pop_front();
          cs_for_neighbours(g, i, [&](size_t j, int) {
            if (solid[j] && cuts.own[j] < 0) cuts.own[j] = cuts.own[i], q.push_back(j);
            return true;
          });
        }
      }
      // Contact of two parts: cells both hold (interpenetration, weighted kOverlapWeight) plus
      // neighbouring cells owned by one and the other (touch, or a gap the closing filled).
      constexpr int64_t kOverlapWeight = 4;
      std::vector<int64_t> overlap(size_t(np) * np, 0), touch(size_t(np) * np, 0);
      {
        for (size_t i = 0; i < g.size(); ++i) {
          const uint64_t m = mask[i];
          if (m & (m - 1))
            for (int a = 0; a < np; ++a)
              if (m >> a & 1)
                for (int b = a + 1; b < np; ++b)
                  if (m >> b & 1) ++overlap[size_t(a) * np + b];
          if (cuts.own[i] < 0) continue;
          cs_for_neighbours(g, i, [&](size_t j, int) {
            const int oi = cuts.own[i], oj = cuts.own[j];
            if (oj >= 0 && oj != oi) ++touch[size_t(std::min(oi, oj)) * np + std::max(oi, oj)];
            return true;
          }, 13, 26);  // each unordered pair of cells once
        }
      }
      // Kruskal, strongest contact first (ties: lower part indices); every pair of parts not
      // joined by the tree is cut.
      std::vector<std::tuple<int64_t, int, int>> edges;
      for (int a = 0; a < np; ++a)
        for (int b = a + 1; b < np; ++b) {
          const int64_t w = kOverlapWeight * overlap[size_t(a) * np + b] + touch[size_t(a) * np + b];
          if (w > 0) edges.emplace_back(-w, a, b);
        }
      std::sort(edges.begin(), edges.end());
      std::vector<int> uf(np);
      for (int p = 0; p < np; ++p) uf[p] = p;
      std::function<int(int)> find = [&](int p) { return uf[p] == p ? p : uf[p] = find(uf[p]); };
      cuts.cut.assign(size_t(np) * np, 1);
      cuts.np = np;
      for (int p = 0; p < np; ++p) cuts.cut[size_t(p) * np + p] = 0;
      // A contact left out of the tree is cut only where it closes a loop around a hole (a forearm
      // against the hip): the shortest way from one side of the contact to the other without
      // crossing it is longer than kLoopDetour times the solid's depth there (+ kLoopSlack cells).
      // Where three parts meet at one joint (an arm, the body and a large head), the way round
      // through the third part is short, and the contact stays.
      constexpr double kLoopDetour = 3.0, kLoopSlack = 6.0;
      std::vector<double> dist(g.size(), std::numeric_limits<double>::infinity());
      std::vector<size_t> touched;
      auto detour_exceeds = [&](int a, int b) {
        auto is_side = [&](size_t i, int self, int other) {
          if (cuts.own[i] != self) return false;
          bool faces = false;
          cs_for_neighbours(g, i, [&](size_t j, int) { return !(faces = cuts.own[j] == other); });
          return faces;
        };
        float depth_max = 0;
        bool b_faces = false;
        for (size_t i = 0; i < g.size(); ++i)
          if (is_side(i, a, b)) dist[i] = 0, touched.push_back(i), depth_max = std::max(depth_max, vs.depth[i]);
          else if (is_side(i, b, a)) depth_max = std::max(depth_max, vs.depth[i]), b_faces = true;
        const std::vector<size_t> sources = touched;
        // No cell of a faces b, or none of b faces a: no step to block.
        const bool reached = sources.empty() || !b_faces ||
                             cs_dijkstra(g, solid, cuts, sources, kLoopDetour * depth_max + kLoopSlack, &dist, &touched,
                                         [&](size_t i) { return cuts.own[i] == b && is_side(i, b, a); });
        for (size_t i : touched) dist[i] = std::numeric_limits<double>::infinity();
        touched.clear();
        return !reached;
      };
      std::vector<uint8_t> in_tree(edges.size(), 0);
      for (size_t e = 0; e < edges.size(); ++e) {
        const auto& [negw, a, b] = edges[e];
        const int ra = find(a), rb = find(b);
        if (ra == rb) continue;
        uf[std::max(ra, rb)] = std::min(ra, rb);
        in_tree[e] = 1;
        cuts.cut[size_t(a) * np + b] = cuts.cut[size_t(b) * np + a] = 0;
      }
      // Each left-out contact is measured against the tree alone (every other one blocked).
      std::vector<uint8_t> keep(edges.size(), 0);
      for (size_t e = 0; e < edges.size(); ++e)
        if (!in_tree[e]) keep[e] = !detour_exceeds(std::get<1>(edges[e]), std::get<2>(edges[e]));
      for (size_t e = 0; e < edges.size(); ++e) {
        const auto& [negw, a, b] = edges[e];
        if (keep[e]) cuts.cut[size_t(a) * np + b] = cuts.cut[size_t(b) * np + a] = 0;
        if (!in_tree[e] && !keep[e]) ++out.num_cut_contacts;
      }
      if (out.num_cut_contacts == 0) cuts = CsCuts();
    }
  }
  size_t n_solid = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < g.size(); ++i)
    if (solid[i]) ++n_solid, centroid += vs.cell_center(i);
  if (n_solid < 64)
    return fail(StatusCode::InvalidMesh, "the mesh gives only " + std::to_string(n_solid) +
                                             " solid cells: too thin or too broken for a skeleton");
  centroid /= double(n_solid);
  if (!progress.update("skeleton: geodesics", 0.5)) return fail(StatusCode::Cancelled, "cancelled during skeleton: geodesics");

  // 3. Geodesic distance from the seed (solid cell nearest the centroid; ties to the lower index).
  size_t seed = 0;
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < g.size(); ++i)
    if (solid[i]) {
      const double d = (vs.cell_center(i) - centroid).squaredNorm();
      if (d < best) best = d, seed = i;
    }
  std::vector<double> geo(g.size(), std::numeric_limits<double>::infinity());
  geo[seed] = 0;
  cs_dijkstra(g, solid, cuts, {seed}, std::numeric_limits<double>::infinity(), &geo, nullptr, [](size_t) { return false; });
  if (!progress.update("skeleton: bands", 0.75)) return fail(StatusCode::Cancelled, "cancelled during skeleton: bands");

  // 4. Bands and their components: the Reeb graph nodes.
  std::vector<int> band(g.size(), -1);
  for (size_t i = 0; i < g.size(); ++i)
    if (solid[i] && std::isfinite(geo[i])) band[i] = int(geo[i] / opt.band_width);
  std::vector<int> comp;
  const int nn = cs_components(g, band, &comp, &cuts);
  std::vector<Eigen::Vector3d> sum(nn, Eigen::Vector3d::Zero());
  std::vector<int> cnt(nn, 0), node_band(nn, 0);
  std::vector<float> rmax(nn, 0.f);
  for (size_t i = 0; i < g.size(); ++i) {
    const int c = comp[i];
    if (c < 0) continue;
    sum[c] += vs.cell_center(i);
    ++cnt[c];
    node_band[c] = band[i];
    rmax[c] = std::max(rmax[c], vs.depth[i]);
  }
  // Contacts between components of consecutive bands: parent = the lower-band component with most contacts.
  std::vector<std::vector<std::pair<int, int>>> contacts(nn);  // (lower component, count)
  for (size_t i = 0; i < g.size(); ++i) {
    if (comp[i] < 0) continue;
    cs_for_neighbours(g, i, [&](size_t j, int) {
      if (comp[j] < 0 || band[j] != band[i] - 1 || cuts.blocked(i, j)) return true;
      auto& v = contacts[comp[i]];
      auto it = std::find_if(v.begin(), v.end(), [&](const std::pair<int, int>& e) { return e.first == comp[j]; });
      if (it == v.end()) v.push_back({comp[j], 1});
      else ++it->second;
      return true;
    });
  }
  std::vector<int> par(nn, -1);
  const int root = comp[seed];
  for (int c = 0; c < nn; ++c) {
    int bestc = -1, bestn = 0;
    for (const auto& [o, n] : contacts[c])
      if (n > bestn || (n == bestn && o < bestc)) bestn = n, bestc = o;
    par[c] = bestc;
  }
  par[root] = -1;
  // Components not linked to the root (cannot happen for band_width ≥ √3) are dropped.
  std::vector<Eigen::Vector3d> pos(nn);
  for (int c = 0; c < nn; ++c) pos[c] = sum[c] / std::max(1, cnt[c]);

  // 5. Prune short leaf branches bottom-up: process nodes by decreasing band.
  std::vector<int> order(nn);
  for (int c = 0; c < nn; ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return node_band[a] > node_band[b]; });
  std::vector<std::vector<int>> kids(nn);
  for (int c = 0; c < nn; ++c)
    if (par[c] >= 0) kids[par[c]].push_back(c);
  std::vector<double> reach(nn, 0.0);  // longest path length from the node down to a leaf of its subtree
  std::vector<double> greach(nn, 0.0); // ... in geodesic bands × band width
  std::vector<uint8_t> alive(nn, 1);
  const double prune = opt.prune_length * L;
  std::function<void(int)> kill = [&](int c) {
    alive[c] = 0;
    for (int k : kids[c]) kill(k);
  };
  for (int c : order) {
    double longest = -1;
    int keep = -1;
    for (int k : kids[c]) {
      const double len = reach[k] + (pos[k] - pos[c]).norm();
      if (len > longest) longest = len, keep = k;
    }
    // A side branch is pruned when shorter than prune_length or than the local radius (bumps,
    // and the fragments a band's ring breaks into where a limb's cap is cut obliquely); the
    // limb's own tip likewise when shorter than the radius (the node then ends the limb).
    // The local radius: depth of the solid at the node's centroid (a band component near the
    // surface, where a blocky part's corners split off, has a small own depth but sits in a thick part).
    const double r_here = std::max<double>(rmax[c] + 0.5, vs.depth[vs.grid.index(vs.grid.coord(pos[c][0], 0), vs.grid.coord(pos[c][1], 1),
                                                                          vs.grid.coord(pos[c][2], 2))]) * h;
    // A side branch's length is also measured along the geodesic (bands × band width): where a
    // wide part's shell breaks up at small bumps (a robot head's bolts), the fragment's centroid
    // lies far from its parent ring's, though it spans only a band or two.
    double kept = 0, gkept = 0;
    for (int k : kids[c]) {
      const double len = reach[k] + (pos[k] - pos[c]).norm(), glen = greach[k] + opt.band_width * h;
      const bool split = kids[c].size() >= 2, side = k != keep;
      if (split && ((side && std::min(len, glen) < std::max(prune, opt.prune_radius * r_here)) || (!side && len < opt.prune_radius * r_here)))
        kill(k);
      else kept = std::max(kept, len), gkept = std::max(gkept, glen);
    }
    (void)longest;
    reach[c] = kept;
    greach[c] = gkept;
  }
  // The root's side branches: the root is usually mid-body, so its shortest remaining branch
  // can also be a stub; the rule above handles it as for any junction.
  std::vector<int> reachable(nn, 0);
  for (int c : std::vector<int>(order.rbegin(), order.rend()))  // increasing band: parents first
    reachable[c] = c == root ? 1 : (par[c] >= 0 && reachable[par[c]] && alive[c]);
  std::vector<int> new_id(nn, -1);
  int m = 0;
  for (int c = 0; c < nn; ++c)
    if (reachable[c]) new_id[c] = m++;
  out.nodes.resize(m, 3);
  out.radius.resize(m);
  out.parent.assign(m, -1);
  for (int c = 0; c < nn; ++c) {
    if (new_id[c] < 0) continue;
    out.nodes.row(new_id[c]) = pos[c].transpose();
    out.radius[new_id[c]] = (rmax[c] + 0.5) * h;
    out.parent[new_id[c]] = c == root ? -1 : new_id[par[c]];
  }
  out.root = new_id[root];
  // Limb tips: the last bands of a limb are rings on its cap whose centroids drift toward the
  // cells the (discrete) geodesic reaches last, so the chain bends off the axis in its last
  // radius. Each tip chain is cut back by one local radius and extended straight along the
  // remaining chain's direction to where it leaves the solid.
  {
    const auto adj0 = out.adjacency();
    std::vector<uint8_t> drop(m, 0);
    for (int leaf = 0; leaf < m; ++leaf) {
      if (adj0[leaf].size() != 1 || leaf == out.root) continue;
      std::vector<int> chain = {leaf};
      double arc = 0, rmax_chain = out.radius[leaf];
      int a = leaf;
      while (out.parent[a] >= 0 && adj0[out.parent[a]].size() == 2 && out.parent[a] != out.root) {
        arc += (out.nodes.row(out.parent[a]) - out.nodes.row(a)).norm();
        a = out.parent[a];
        chain.push_back(a);
        rmax_chain = std::max(rmax_chain, out.radius[a]);
        if (arc >= rmax_chain) break;
      }
      if (chain.size() < 2 || arc < rmax_chain) continue;  // short tips are left as they are
      // Direction from one more radius up the chain to the anchor a.
      int b = a;
      double back = 0;
      while (out.parent[b] >= 0 && back < out.radius[a]) {
        back += (out.nodes.row(out.parent[b]) - out.nodes.row(b)).norm();
        b = out.parent[b];
      }
      Eigen::Vector3d d = (out.nodes.row(a) - out.nodes.row(b)).transpose();
      if (d.norm() <= 0) continue;
      d.normalize();
      Eigen::Vector3d e = out.nodes.row(a).transpose();
      for (int step = 0; step < 4 * opt.resolution && vs.contains(e + 0.5 * h * d); ++step) e += 0.5 * h * d;
      for (size_t k = 1; k + 1 < chain.size(); ++k) drop[chain[k]] = 1;
      out.nodes.row(leaf) = e.transpose();
      out.radius[leaf] = 0.5 * h;
      out.parent[leaf] = a;
    }
    // The first bands are concentric shells around the seed with (nearly) the same centroid: a
    // root with a single child that close is dropped, and so on down the chain.
    int new_root = out.root;
    for (;;) {
      std::vector<int> kids_of_root;
      for (int i = 0; i < m; ++i)
        if (out.parent[i] == new_root && !drop[i]) kids_of_root.push_back(i);
      if (kids_of_root.size() != 1) break;
      const int kid = kids_of_root[0];
      if ((out.nodes.row(kid) - out.nodes.row(new_root)).norm() > 0.5 * out.radius[new_root]) break;
      drop[new_root] = 1;
      out.parent[kid] = -1;
      new_root = kid;
    }
    out.root = new_root;
    std::vector<int> id(m, -1);
    int k = 0;
    for (int i = 0; i < m; ++i)
      if (!drop[i]) id[i] = k++;
    Eigen::MatrixXd P(k, 3);
    Eigen::VectorXd R(k);
    std::vector<int> par2(k, -1);
    for (int i = 0; i < m; ++i) {
      if (drop[i]) continue;
      P.row(id[i]) = out.nodes.row(i);
      R[id[i]] = out.radius[i];
      par2[id[i]] = out.parent[i] >= 0 ? id[out.parent[i]] : -1;
    }
    out.nodes = P;
    out.radius = R;
    out.parent = par2;
    out.root = id[out.root];
    m = k;
  }
  // Smooth chain nodes (degree 2): removes the stair-steps of the band centroids.
  const auto adj = out.adjacency();
  for (int it = 0; it < opt.smoothing_iterations; ++it) {
    Eigen::MatrixXd P = out.nodes;
    for (int i = 0; i < m; ++i)
      if (adj[i].size() == 2) P.row(i) = 0.5 * out.nodes.row(i) + 0.25 * (out.nodes.row(adj[i][0]) + out.nodes.row(adj[i][1]));
    out.nodes = P;
  }
  if (!out.nodes.allFinite()) return fail(StatusCode::NumericalError, "the skeleton has non-finite nodes");
  progress.update("skeleton", 1.0);
  return out;
}

}  // namespace mm
