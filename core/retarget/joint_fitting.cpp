#include "retarget/joint_fitting.h"

#include <algorithm>
#include <functional>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>

#include "common/threads.h"
#include "retarget/bone_blend.h"
#include "spatial/triangle_bvh.h"
#include "spatial/uniform_grid.h"

namespace mm {

namespace joint_fitting_detail {

Eigen::Vector3d jf_axis(int a) {
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  u[a % 3] = a < 3 ? 1.0 : -1.0;
  return u;
}

const char* jf_axis_name(int a) {
  static const char* names[6] = {"+x", "+y", "+z", "-x", "-y", "-z"};
  return names[a];
}

// The 24 proper axis-aligned rotations, in a fixed order.
std::vector<Eigen::Matrix3d> jf_rotations() {
  std::vector<Eigen::Matrix3d> out;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms)
    for (int s = 0; s < 8; ++s) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) R(i, p[i]) = (s >> i) & 1 ? -1.0 : 1.0;
      if (R.determinant() > 0) out.push_back(R);
    }
  return out;
}

// Normalised frame of a point set seen with up vector u: origin at the bottom centre of the
// bounding box, unit = the extent along u.
struct JfFrame {
  Eigen::Vector3d o = Eigen::Vector3d::Zero();
  double H = 1;
  Eigen::Vector3d u = Eigen::Vector3d::UnitY();
  Eigen::Vector3d operator()(const Eigen::Vector3d& p) const { return (p - o) / H; }
  double height(const Eigen::Vector3d& p) const { return (p - o).dot(u) / H; }
};

JfFrame jf_frame(const Eigen::MatrixXd& P, const Eigen::Vector3d& u) {
  JfFrame f;
  const Eigen::Vector3d lo = P.colwise().minCoeff().transpose(), hi = P.colwise().maxCoeff().transpose();
  const double ext = (hi - lo).cwiseAbs().dot(u.cwiseAbs());
  f.u = u;
  f.H = ext > 0 ? ext : 1.0;
  f.o = 0.5 * (lo + hi) - 0.5 * ext * u;
  return f;
}

// A rooted tree view of a curve skeleton with paths, lowest common ancestors and medians.
struct JfTree {
  const CurveSkeleton* s = nullptr;
  std::vector<int> depth, children;
  explicit JfTree(const CurveSkeleton& sk) : s(&sk), depth(sk.size(), 0), children(sk.size(), 0) {
    for (int i = 0; i < sk.size(); ++i) {
      int d = 0;
      for (int p = sk.parent[i]; p >= 0; p = sk.parent[p]) ++d;
      depth[i] = d;
      if (sk.parent[i] >= 0) ++children[sk.parent[i]];
    }
  }
  int lca(int a, int b) const {
    while (depth[a] > depth[b]) a = s->parent[a];
    while (depth[b] > depth[a]) b = s->parent[b];
    while (a != b) a = s->parent[a], b = s->parent[b];
    return a;
  }
  int median(int a, int b, int c) const {
    const int x = lca(a, b), y = lca(a, c), z = lca(b, c);
    int m = x;
    if (depth[y] > depth[m]) m = y;
    if (depth[z] > depth[m]) m = z;
    return m;
  }
  std::vector<int> path(int a, int b) const {
    const int l = lca(a, b);
    std::vector<int> up, down;
    for (int x = a; x != l; x = s->parent[x]) up.push_back(x);
    up.push_back(l);
    for (int x = b; x != l; x = s->parent[x]) down.push_back(x);
    up.insert(up.end(), down.rbegin(), down.rend());
    return up;
  }
  Eigen::Vector3d pos(int i) const { return s->nodes.row(i).transpose(); }
};

// A path with cumulative arc lengths.
struct JfPath {
  std::vector<int> nodes;
  std::vector<double> arc;
  double length() const { return arc.empty() ? 0 : arc.back(); }
  int index_of(int node) const {
    for (size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i] == node) return int(i);
    return -1;
  }
};

JfPath jf_path(const JfTree& t, int a, int b) {
  JfPath p;
  p.nodes = t.path(a, b);
  p.arc.assign(p.nodes.size(), 0.0);
  for (size_t i = 1; i < p.nodes.size(); ++i) p.arc[i] = p.arc[i - 1] + (t.pos(p.nodes[i]) - t.pos(p.nodes[i - 1])).norm();
  return p;
}

// Point and radius at arc length s along a path (clamped).
void jf_point_at(const JfTree& t, const JfPath& p, double s, Eigen::Vector3d* x, double* r) {
  s = std::clamp(s, 0.0, p.length());
  size_t i = 0;
  while (i + 2 < p.nodes.size() && p.arc[i + 1] < s) ++i;
  if (p.nodes.size() == 1) {
    *x = t.pos(p.nodes[0]);
    *r = t.s->radius[p.nodes[0]];
    return;
  }
  const double len = p.arc[i + 1] - p.arc[i];
  const double u = len > 0 ? std::clamp((s - p.arc[i]) / len, 0.0, 1.0) : 0.0;
  *x = (1 - u) * t.pos(p.nodes[i]) + u * t.pos(p.nodes[i + 1]);
  *r = (1 - u) * t.s->radius[p.nodes[i]] + u * t.s->radius[p.nodes[i + 1]];
}

// Solid cell centres, every stride-th, as rows.
Eigen::MatrixXd jf_solid_samples(const VoxelSolid& v, int target_count) {
  size_t n = 0;
  for (uint8_t s : v.solid) n += s;
  const size_t stride = std::max<size_t>(1, n / std::max(1, target_count));
  std::vector<Eigen::Vector3d> pts;
  size_t k = 0;
  for (size_t i = 0; i < v.solid.size(); ++i)
    if (v.solid[i] && (k++ % stride) == 0) pts.push_back(v.cell_center(i));
  Eigen::MatrixXd P(pts.size(), 3);
  for (size_t i = 0; i < pts.size(); ++i) P.row(i) = pts[i].transpose();
  return P;
}

// Chamfer distance of two point sets (step 3's facing score): the mean distance from each point of
// one to the nearest of the other, averaged both ways. Nearest points through a PointGrid
// (spatial/uniform_grid.h), ~2 points per cell: the same bits as a brute-force minimum, ~10×
// faster at 1,200 × 1,200 samples (for each of four turns).
double jf_chamfer(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  auto one_way = [](const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
    if (X.rows() == 0) return 0.0;
    const PointGrid grid(Y, std::max(1, static_cast<int>(std::lround(std::cbrt(Y.rows() / 2.0)))));
    double sum = 0;
    for (int i = 0; i < X.rows(); ++i) {
      const double p[3] = {X(i, 0), X(i, 1), X(i, 2)};
      sum += std::sqrt(grid.nearest_sq_distance(p));
    }
    return sum / static_cast<double>(X.rows());
  };
  return 0.5 * (one_way(A, B) + one_way(B, A));
}

struct JfLeafMatch {
  std::vector<std::pair<int, int>> pairs;  // (source leaf node, target leaf node)
  double cost = 0;
};

// Minimum-cost assignment (Kuhn–Munkres with potentials, O(n² m)) of the rows of C (n ≤ m) to
// distinct columns; returns the column of each row.
std::vector<int> jf_assignment(const Eigen::MatrixXd& C) {
  const int n = static_cast<int>(C.rows()), m = static_cast<int>(C.cols());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0), v(m + 1, 0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);  // p[j]: row (1-based) assigned to column j
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<uint8_t> used(m + 1, 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = C(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) minv[j] = cur, way[j] = j0;
        if (minv[j] < delta) delta = minv[j], j1 = j;
      }
      for (int j = 0; j <= m; ++j)
        if (used[j]) u[p[j]] += delta, v[j] -= delta;
        else minv[j] -= delta;
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0);
  }
  std::vector<int> col(n, -1);
  for (int j = 1; j <= m; ++j)
    if (p[j] > 0) col[p[j] - 1] = j - 1;
  return col;
}

// Matching of normalised limb ends with the least total cost: each source end takes a distinct
// target end within tol, or none at a cost of tol (an assignment with one "unmatched" column per
// source end). It replaced a greedy closest-first matching, which a close pair taken early can
// lead astray; on every pair in the tests both give the same matches (the KayKit Knight's bones
// in human_woman still pair the left hand with a bump at her left shoulder: with the Knight's
// large head its hands sit at 0.43 of the height, hers at 0.80, and that bump is the cheaper end).
JfLeafMatch jf_match_leaves(const std::vector<Eigen::Vector3d>& S, const std::vector<int>& s_nodes,
                            const std::vector<Eigen::Vector3d>& T, const std::vector<int>& t_nodes, double tol) {
  const int ns = static_cast<int>(S.size() / 2), nt = static_cast<int>(T.size() / 2);
  JfLeafMatch m;
  if (ns == 0) return m;
  // S, T: two points per limb end (end, back point); the cost is their mean distance.
  Eigen::MatrixXd C = Eigen::MatrixXd::Constant(ns, nt + ns, 1e6);
  for (int i = 0; i < ns; ++i) {
    for (int j = 0; j < nt; ++j) {
      const double d = 0.5 * ((S[2 * i] - T[2 * j]).norm() + (S[2 * i + 1] - T[2 * j + 1]).norm());
      if (d <= tol) C(i, j) = d;
    }
    C(i, nt + i) = tol;
  }
  const std::vector<int> col = jf_assignment(C);
  for (int i = 0; i < ns; ++i) {
    if (col[i] >= 0 && col[i] < nt && C(i, col[i]) <= tol) {
      m.pairs.push_back({s_nodes[i], t_nodes[col[i]]});
      m.cost += C(i, col[i]);
    } else {
      m.cost += tol;
    }
  }
  return m;
}

// Where a limb joins the body: the node of the tree spanned by the matched limb ends (paths
// between them) closest to `leaf` along the tree — the projections median(leaf, a, b) over
// matched ends a, b (lca(leaf, a) for a single end), the one fewest edges from the leaf. Returns
// the node and the path's arc length from the leaf to it.
std::pair<int, double> jf_attachment(const JfTree& t, int leaf, const std::vector<int>& matched) {
  auto edges_from_leaf = [&](int m) { return t.depth[leaf] + t.depth[m] - 2 * t.depth[t.lca(leaf, m)]; };
  int best = -1;
  for (size_t i = 0; i < matched.size(); ++i)
    for (size_t j = i; j < matched.size(); ++j) {
      const int m = j == i ? t.lca(leaf, matched[i]) : t.median(leaf, matched[i], matched[j]);
      if (best < 0 || edges_from_leaf(m) < edges_from_leaf(best)) best = m;
    }
  if (best < 0) return {leaf, 0.0};
  return {best, jf_path(t, leaf, best).length()};
}

// Step 4, second pass: source limb ends that carry joints and found no partner by position (a
// robot's hanging arms against a T-pose) paired with the target's unmatched limb ends by where
// they join the matched body and where their middles lie (normalised frames, target turned by R),
// when they join within `tol` × height of each other and their lengths differ by less than 2×.
// Appends to m->pairs; returns the source ends paired.
std::vector<int> jf_match_by_attachment(const JfTree& st, const JfTree& tt, const std::vector<int>& s_free,
                                        const std::vector<int>& t_free, JfLeafMatch* m,
                                        const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& fs,
                                        const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& ft, double tol) {
  std::vector<int> sm, tm, paired;
  for (const auto& pr : m->pairs) sm.push_back(pr.first), tm.push_back(pr.second);
  if (s_free.empty() || t_free.empty() || m->pairs.empty()) return paired;
  struct Limb {
    Eigen::Vector3d join, middle;
    double length;
  };
  auto limb = [](const JfTree& t, int leaf, const std::vector<int>& matched,
                 const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& f) {
    const auto [node, arc] = jf_attachment(t, leaf, matched);
    Eigen::Vector3d mid;
    double radius;
    const JfPath p = jf_path(t, leaf, node);
    jf_point_at(t, p, 0.5 * arc, &mid, &radius);
    const Eigen::Vector3d join = f(t.pos(node));
    double length = 0;  // normalised: the path's length in the frame's units
    for (size_t i = 1; i < p.nodes.size(); ++i) length += (f(t.pos(p.nodes[i])) - f(t.pos(p.nodes[i - 1]))).norm();
    return Limb{join, f(mid), length};
  };
  const int ns = int(s_free.size()), nt = int(t_free.size());
  std::vector<Limb> ls, lt;
  for (int l : s_free) ls.push_back(limb(st, l, sm, fs));
  for (int l : t_free) lt.push_back(limb(tt, l, tm, ft));
  Eigen::MatrixXd C = Eigen::MatrixXd::Constant(ns, nt + ns, 1e6);
  for (int i = 0; i < ns; ++i) {
    for (int j = 0; j < nt; ++j) {
      const double dj = (ls[i].join - lt[j].join).norm();
      const double ratio = std::max(ls[i].length, lt[j].length) / std::max(1e-12, std::min(ls[i].length, lt[j].length));
      if (dj <= tol && ratio < 2) C(i, j) = 0.5 * (dj + (ls[i].middle - lt[j].middle).norm());
    }
    C(i, nt + i) = 2 * tol;
  }
  const std::vector<int> col = jf_assignment(C);
  for (int i = 0; i < ns; ++i)
    if (col[i] >= 0 && col[i] < nt && C(i, col[i]) < 1e6) {
      m->pairs.push_back({s_free[i], t_free[col[i]]});
      paired.push_back(s_free[i]);
    }
  return paired;
}

// The source's joint tree as a skeleton (SourceSkeleton::Bones): nodes = the joints of `used`
// in the largest connected part of the hierarchy (parent = nearest used ancestor), plus one tip
// node per leaf joint, where its bone, prolonged, leaves the source's solid — the limb's end, as
// the target's curve skeleton ends at the tip of the limb. Radius = distance to the surface. The
// volume is the voxel skeleton's (for the facing test). Joints of other parts (IK helpers inside
// the surface) are not nodes: they are placed from their closest point on the tree (step 5).
CurveSkeleton jf_bone_skeleton(const CurveSkeleton& voxel, const JointSet& J, const std::vector<int>& used,
                               const TriangleBvh& bvh) {
  CurveSkeleton out;
  out.volume = voxel.volume;
  out.num_bridges = voxel.num_bridges;
  const int nj = J.size();
  std::vector<uint8_t> is_used(nj, 0);
  for (int j : used) is_used[j] = 1;
  const bool has_tree = static_cast<int>(J.parent.size()) == nj;
  std::vector<int> up(nj, -1);  // nearest used ancestor
  for (int j : used) {
    int p = has_tree ? J.parent[j] : -1;
    while (p >= 0 && !is_used[p]) p = J.parent[p];
    up[j] = p;
  }
  // Largest part: count used descendants of each top (used joint without a used ancestor).
  std::vector<int> top(nj, -1), size(nj, 0);
  for (int j : used) {
    int t = j;
    while (up[t] >= 0) t = up[t];
    top[j] = t;
    ++size[t];
  }
  int root = -1;
  for (int j : used)
    if (up[j] < 0 && (root < 0 || size[j] > size[root])) root = j;
  if (root < 0) {
    out.status = Status::error(StatusCode::InvalidArgument, "the source has no joints inside its surface");
    return out;
  }
  std::vector<int> node_of(nj, -1), joint_of;
  for (int j : used)
    if (top[j] == root) node_of[j] = static_cast<int>(joint_of.size()), joint_of.push_back(j);
  std::vector<int> children(nj, 0);
  for (int j : joint_of)
    if (up[j] >= 0) ++children[up[j]];
  std::vector<Eigen::Vector3d> pos;
  for (int j : joint_of) {
    pos.push_back(J.P.row(j).transpose());
    out.parent.push_back(up[j] >= 0 ? node_of[up[j]] : -1);
  }
  const double step = 0.25 * voxel.volume.grid.cell;
  const UniformGrid& g = voxel.volume.grid;  // no walk inside the solid is longer than its grid's diagonal
  const double reach = g.cell * std::sqrt(double(g.dims[0]) * g.dims[0] + double(g.dims[1]) * g.dims[1] +
                                          double(g.dims[2]) * g.dims[2]);
  for (int j : joint_of) {
    if (children[j] > 0 || up[j] < 0) continue;
    const Eigen::Vector3d a = J.P.row(up[j]).transpose(), b = J.P.row(j).transpose();
    const Eigen::Vector3d d = b - a;
    if (!(d.norm() > 0)) continue;
    const Eigen::Vector3d u = d.normalized();
    Eigen::Vector3d tip = b;
    for (double s = step; s < reach && voxel.volume.contains(b + s * u); s += step) tip = b + s * u;
    if ((tip - b).norm() < step) continue;
    pos.push_back(tip);
    out.parent.push_back(node_of[j]);
  }
  out.nodes.resize(static_cast<Eigen::Index>(pos.size()), 3);
  out.radius.resize(static_cast<Eigen::Index>(pos.size()));
  for (size_t i = 0; i < pos.size(); ++i) {
    out.nodes.row(static_cast<Eigen::Index>(i)) = pos[i].transpose();
    out.radius[static_cast<Eigen::Index>(i)] = std::max(std::sqrt(bvh.closest_point(pos[i]).sq_distance), step);
  }
  out.root = node_of[root];
  return out;
}

// Bones between joints (parent[i] = i's parent, −1 for a root) as neighbour lists, and the hops
// from the joints `from` along them, at most `reach`, never through a `blocked` joint (another
// marker's: step 6 and the topology check's markers reach the same joints). −1 = not reached.
std::vector<std::vector<int>> jf_bone_adjacency(const std::vector<int>& parent) {
  std::vector<std::vector<int>> adj(parent.size());
  for (size_t i = 0; i < parent.size(); ++i)
    if (parent[i] >= 0) adj[i].push_back(parent[i]), adj[parent[i]].push_back(int(i));
  return adj;
}
std::vector<int> jf_hops(const std::vector<std::vector<int>>& adj, const std::vector<int>& from, int reach,
                         const std::vector<uint8_t>& blocked) {
  std::vector<int> hop(adj.size(), -1);
  std::vector<int> q = from;
  for (int k : from) hop[k] = 0;
  for (size_t h = 0; h < q.size(); ++h)
    for (int nb : adj[q[h]])
      if (hop[nb] < 0 && hop[q[h]] < reach && !blocked[nb]) hop[nb] = hop[q[h]] + 1, q.push_back(nb);
  return hop;
}

std::string jf_join(const std::vector<std::string>& v, size_t limit = 10) {
  std::string s;
  for (size_t i = 0; i < v.size() && i < limit; ++i) s += (i ? ", " : "") + v[i];
  if (v.size() > limit) s += ", ... (" + std::to_string(v.size()) + " in all)";
  return s;
}

// Touching legs (step 4b). A biped whose thighs touch (human_woman) is one solid from the crotch
// down to the knees, so its curve skeleton forks at the knees and the hips, spine and legs are
// fitted 0.1–0.3 of the height low. Seen across the trunk just above such a fork, the solid is
// two thighs side by side: thinner front to back between them than through each. Walking up the
// trunk while that groove holds (centre thickness < groove_ratio × the thinner side, the sides at
// the legs' half separation just below the fork) finds the crotch; the fork is moved to the trunk's
// medial junction above it (not past another branch) and each leg continued up to it, side by side
// at that separation to the crotch and converging above it. feet/head: leaf nodes; vertical: the
// character's up axis in the skeleton's coordinates. Returns the old → new node index map, or
// empty when nothing changed.
std::vector<int> jf_split_touching_legs(CurveSkeleton* T, const JfTree& tt, const std::array<int, 2>& feet, int head,
                                        const Eigen::Vector3d& vertical, double groove_ratio) {
  const int fork_t = tt.median(feet[0], feet[1], head);
  const auto adj = T->adjacency();
  if (adj[fork_t].size() != 3) return {};
  // The legs' nodes just below the old fork, and their half separation across the trunk.
  const JfPath trunk = jf_path(tt, fork_t, head);
  if (trunk.nodes.size() < 3) return {};
  std::array<int, 2> below{};
  for (int i = 0; i < 2; ++i) {
    const JfPath leg = jf_path(tt, feet[i], fork_t);
    if (leg.nodes.size() < 2) return {};
    below[i] = leg.nodes[leg.nodes.size() - 2];
  }
  const Eigen::Vector3d up = (tt.pos(trunk.nodes[std::min<size_t>(3, trunk.nodes.size() - 1)]) - tt.pos(fork_t)).normalized();
  Eigen::Vector3d half = 0.5 * (tt.pos(below[0]) - tt.pos(below[1]));
  half -= half.dot(up) * up;
  const Eigen::Vector3d depth_dir = up.cross(half).normalized();
  if (!up.allFinite() || !depth_dir.allFinite() || half.norm() <= 0) return {};
  const VoxelSolid& solid = T->volume;
  const double step = 0.5 * solid.grid.cell;
  // Extent of the solid from p to its front (+depth_dir) and to its back (0 when p is outside).
  auto extents = [&](const Eigen::Vector3d& p) {
    std::array<double, 2> e{0, 0};
    if (!solid.contains(p)) return e;
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? 1.0 : -1.0;
      for (int k = 1; k < 4096 && solid.contains(p + sign * k * step * depth_dir); ++k) e[side] += step;
    }
    return e;
  };
  // A groove between the legs: thinner front to back at the centre than through either leg.
  auto grooved = [&](const Eigen::Vector3d& c) {
    const auto m = extents(c), a = extents(c + half), b = extents(c - half);
    return m[0] + m[1] < groove_ratio * std::min(a[0] + a[1], b[0] + b[1]);
  };
  // Up the trunk from the old fork while the groove holds, not past another branch.
  int k = 0;
  while (k + 1 < int(trunk.nodes.size()) && adj[trunk.nodes[k + 1]].size() == 2) {
    if (!grooved(tt.pos(trunk.nodes[k + 1]))) break;
    ++k;
  }
  if (k == 0 || k + 1 >= int(trunk.nodes.size())) return {};
  // The fork goes where a pair of separate legs has it: the medial axis of a Y branches at the
  // centre of the largest ball that touches the crotch, about one trunk radius above it. The
  // crotch is the groove's end (node k) when the trunk below it stays solid deeper than its radius
  // (thighs that touch), else the top of the gap below (the groove was a buttocks' cleft above
  // legs that are apart: CesiumMan, gap 0.056 of his height). The junction is the first trunk node
  // above the crotch whose radius no longer exceeds its distance from it, not past another branch.
  // Measured: CesiumMan's junction stays at his groove's end, 0.409 of his height (his hip joints
  // 0.408); human_woman's moves from her crotch, 0.431, to 0.510 (her hand-placed hips 0.516).
  const Eigen::Vector3d crotch_top = tt.pos(trunk.nodes[k]);
  const double r_crotch = T->radius[trunk.nodes[k]];
  double gap = 0;
  while (gap <= 1.5 * r_crotch && solid.contains(crotch_top - gap * vertical)) gap += step;
  if (gap > 1.5 * r_crotch) gap = 0;
  int junction = k;
  while (junction + 1 < int(trunk.nodes.size()) && adj[trunk.nodes[junction]].size() == 2 &&
         gap + trunk.arc[junction] - trunk.arc[k] < T->radius[trunk.nodes[junction]])
    ++junction;
  if (junction + 1 >= int(trunk.nodes.size())) junction = k;
  // Rebuild: drop trunk nodes 0..junction−1, add one chain per leg from its node below to the
  // junction: side by side at the legs' half separation up to the crotch, converging above it.
  const int n = T->size();
  std::vector<uint8_t> drop(n, 0);
  for (int i = 0; i < junction; ++i) drop[trunk.nodes[i]] = 1;
  std::vector<int> remap(n, -1);
  std::vector<Eigen::Vector3d> pos;
  std::vector<double> radius;
  for (int v = 0; v < n; ++v)
    if (!drop[v]) remap[v] = int(pos.size()), pos.push_back(T->nodes.row(v).transpose()), radius.push_back(T->radius[v]);
  std::vector<std::vector<int>> nb(pos.size());
  auto link = [&](int a, int b) { nb[a].push_back(b), nb[b].push_back(a); };
  for (int v = 0; v < n; ++v)
    if (T->parent[v] >= 0 && !drop[v] && !drop[T->parent[v]]) link(remap[v], remap[T->parent[v]]);
  for (int i = 0; i < 2; ++i) {
    int prev = remap[below[i]];
    const double sign = i == 0 ? 1.0 : -1.0;
    for (int j = 0; j < junction; ++j) {
      const int id = int(pos.size());
      const double above = j <= k ? 0.0 : (trunk.arc[j] - trunk.arc[k]) / (trunk.arc[junction] - trunk.arc[k]);
      pos.push_back(tt.pos(trunk.nodes[j]) + sign * (1 - above) * half);
      radius.push_back(T->radius[below[i]]);
      nb.emplace_back();
      link(prev, id);
      prev = id;
    }
    link(prev, remap[trunk.nodes[junction]]);
  }
  const int m = int(pos.size());
  const int root = remap[T->root] >= 0 ? remap[T->root] : remap[trunk.nodes[junction]];
  std::vector<int> parent(m, -2);
  parent[root] = -1;
  std::vector<int> queue = {root};
  for (size_t q = 0; q < queue.size(); ++q)
    for (int w : nb[queue[q]])
      if (parent[w] == -2) parent[w] = queue[q], queue.push_back(w);
  if (int(queue.size()) != m) return {};  // not a tree any more: leave the skeleton as it was
  T->nodes.resize(m, 3);
  T->radius.resize(m);
  for (int i = 0; i < m; ++i) T->nodes.row(i) = pos[i].transpose(), T->radius[i] = radius[i];
  T->parent = parent;
  T->root = root;
  return remap;
}

// Step 5b: each placed joint moved by how the source surface around it lands on the target.
// The source surface is carried into the target's frame (the similarity of steps 2–3), posed onto
// the fitted joints bone by bone (articulated_points), and each of its vertices paired with the
// closest target point. A joint then takes the local affine map of those pairs (Gaussian weights
// by the vertex's distance from the source joint, σ = surface_refine_sigma × the joint's depth
// below the source surface, ridge toward a translation): a joint centred in a thigh stays centred
// in a thicker thigh. Repeated `surface_refine_iterations` times (the pose follows the moved
// joints); a move that would leave the target is not taken. Js: the placed joints' source
// positions (rows of `out`).
// The surface around a joint is the part of it seen from the joint through the source's solid
// (`solid`, the voxel proxy of its skeleton, holes closed: a many-part robot's small gaps between
// its pieces do not hide them; null = every vertex within reach): the segment from the joint to a
// vertex stays inside at 7 evenly spaced points. Without it the Knight's knee took its other leg
// (29 % of the weight) and was pulled toward CesiumMan's other leg: 5.4 % of his height from his
// knee; with it, Knight → CesiumMan 3.16 → 2.67 % over the 10 key joints (forty-eighth session).
void jf_refine_by_surface(const Eigen::MatrixXd& Vs, const Eigen::MatrixXi& Fs, const Eigen::MatrixXd& Js,
                          const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& to_target,
                          const TriangleBvh& bvh_s, const TriangleBvh& bvh_t, const std::function<bool(const Eigen::Vector3d&)>& inside_t,
                          const VoxelSolid* solid, double height_s, const JointFitOptions& opt, JointSet* out) {
  const int n = out->size();
  std::vector<std::pair<int, int>> bones;
  for (int i = 0; i < n; ++i)
    if (out->parent[i] >= 0) bones.push_back({i, out->parent[i]});
  if (bones.empty() || Vs.rows() == 0) return;
  // Vertex areas (a third of each incident triangle): uneven tessellation must not tilt the fit.
  Eigen::VectorXd area = Eigen::VectorXd::Zero(Vs.rows());
  for (Eigen::Index f = 0; f < Fs.rows(); ++f) {
    const Eigen::Vector3d a = Vs.row(Fs(f, 0)), b = Vs.row(Fs(f, 1)), c = Vs.row(Fs(f, 2));
    const double A = 0.5 * (b - a).cross(c - a).norm() / 3;
    for (int k = 0; k < 3; ++k) area[Fs(f, k)] += A;
  }
  Eigen::MatrixXd Y0(Vs.rows(), 3), J0(n, 3);
  for (Eigen::Index i = 0; i < Vs.rows(); ++i) Y0.row(i) = to_target(Vs.row(i).transpose()).transpose();
  for (int j = 0; j < n; ++j) J0.row(j) = to_target(Js.row(j).transpose()).transpose();
  // Neighbourhood of each joint on the source, fixed across iterations.
  std::vector<std::vector<std::pair<int, double>>> near(n);
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d pj = Js.row(j).transpose();
    const double depth = std::sqrt(bvh_s.closest_point(pj).sq_distance);
    const double sigma = opt.surface_refine_sigma * std::max(depth, 0.01 * height_s);
    for (Eigen::Index i = 0; i < Vs.rows(); ++i) {
      const double d2 = (Vs.row(i).transpose() - pj).squaredNorm();
      if (d2 > 9 * sigma * sigma || area[i] <= 0) continue;
      if (solid) {
        const Eigen::Vector3d v = Vs.row(i).transpose();
        bool seen = true;
        for (int q = 1; q < 8 && seen; ++q) seen = solid->contains(pj + (q / 8.0) * (v - pj));
        if (!seen) continue;
      }
      near[j].push_back({int(i), area[i] * std::exp(-0.5 * d2 / (sigma * sigma))});
    }
  }
  for (int it = 0; it < opt.surface_refine_iterations; ++it) {
    const Eigen::MatrixXd Y = articulated_points(Y0, J0, out->P, bones);
    Eigen::MatrixXd C(Y.rows(), 3);
    for (Eigen::Index i = 0; i < Y.rows(); ++i) C.row(i) = bvh_t.closest_point(Y.row(i).transpose()).point.transpose();
    Eigen::MatrixXd P = out->P;
    for (int j = 0; j < n; ++j) {
      if (near[j].size() < 4) continue;
      // Weighted least squares [A b] on centred points: C − c̄ ≈ A (Y − ȳ), ridge λ·(A − I).
      double W = 0;
      Eigen::Vector3d yb = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
      for (const auto& [i, w] : near[j]) W += w, yb += w * Y.row(i).transpose(), cb += w * C.row(i).transpose();
      if (!(W > 0)) continue;
      yb /= W, cb /= W;
      Eigen::Matrix3d YY = Eigen::Matrix3d::Zero(), CY = Eigen::Matrix3d::Zero();
      for (const auto& [i, w] : near[j]) {
        const Eigen::Vector3d y = Y.row(i).transpose() - yb, c = C.row(i).transpose() - cb;
        YY += w * y * y.transpose();
        CY += w * c * y.transpose();
      }
      const double lambda = opt.surface_refine_ridge * YY.trace() / 3 + 1e-300;
      const Eigen::Matrix3d A = (CY + lambda * Eigen::Matrix3d::Identity()) * (YY + lambda * Eigen::Matrix3d::Identity()).inverse();
      const Eigen::Vector3d q = cb + A * (out->P.row(j).transpose() - yb);
      if (q.allFinite() && inside_t(q)) P.row(j) = q.transpose();
    }
    out->P = P;
  }
}

// Steps 2–6 on the skeletons in r (the source's tree chosen by the caller). `lost_limbs`: set when
// the fit is refused because a source limb has no partner in the target (the case where the
// source's own bones may still fit, SourceSkeleton::Auto). `markers_lift_lost`: a lost limb with a
// marker on it, or within marker_reach bones of one, is placed from the markers instead.
struct JfInputs {
  const Eigen::MatrixXd &Vs, &Vt;
  const Eigen::MatrixXi &Fs, &Ft;
  const JointSet& source_joints;
  const std::vector<int>& used;
  const TriangleBvh &bvh_s, &bvh_t;
  double tol_t;
  const std::vector<JointMarker>& markers;
  const JointFitOptions& opt;
  const Progress& progress;
  const std::vector<BallPart> &balls_s, &balls_t;  // step 5d
};

// How far fitted bones d are from the source's bones b in the target's frame, Σ|d − b| / Σ|b|
// (0 without bones): step 5c's measure of whether the target is of the source's rig family.
struct BoneAgreement {
  double dev = 0, len = 0;
  void add(const Eigen::Vector3d& d, const Eigen::Vector3d& b) {
    dev += (d - b).norm();
    len += b.norm();
  }
  double ratio() const { return len > 0 ? dev / len : 0; }
};

JointFitResult jf_fit_on_skeletons(JointFitResult r, const JfInputs& in, bool source_is_curve, bool* lost_limbs,
                                   bool markers_lift_lost) {
  const Eigen::MatrixXd &Vs = in.Vs, &Vt = in.Vt;
  const Eigen::MatrixXi& Ft = in.Ft;
  const JointSet& source_joints = in.source_joints;
  const std::vector<int>& used = in.used;
  const TriangleBvh& bvh_t = in.bvh_t;
  const std::vector<JointMarker>& markers = in.markers;
  const JointFitOptions& opt = in.opt;
  const Progress& progress = in.progress;
  const double tol_t = in.tol_t;
  auto inside_t = [&](const Eigen::Vector3d& p) { return bvh_t.closest_point(p).sq_distance <= tol_t * tol_t || bvh_t.inside(p); };
  auto fail = [&](StatusCode c, const std::string& m) {
    r.status = Status::error(c, m);
    return r;
  };
  const CurveSkeleton& SS = r.source_skeleton;
  const CurveSkeleton& TS = r.target_skeleton;
  JfTree st(SS), tt(TS);  // rebuilt when touching legs are split (step 4b)
  const std::vector<int> s_leaves = SS.leaves(), t_leaves = TS.leaves();
  if (s_leaves.size() < 2 || t_leaves.size() < 2)
    return fail(StatusCode::InvalidMesh, std::string("the ") + (s_leaves.size() < 2 ? "source" : "target") +
                                             " skeleton has fewer than 2 limb ends: the mesh is too broken or too "
                                             "blob-like for automatic joints; place the joints with markers or a JSON file");

  // 2. Up axes.
  const Eigen::Vector3d us = jf_axis(opt.source_up);
  Eigen::MatrixXd Ls(s_leaves.size(), 3), Lt(t_leaves.size(), 3);
  for (size_t i = 0; i < s_leaves.size(); ++i) Ls.row(i) = SS.nodes.row(s_leaves[i]);
  for (size_t i = 0; i < t_leaves.size(); ++i) Lt.row(i) = TS.nodes.row(t_leaves[i]);
  int up_t = opt.target_up;
  if (up_t < 0) {
    // Only axes along which the body is tall enough to stand on: limb ends cluster at either end
    // of a thin axis too (human_woman's back, 0.18 of her height deep, held 3 ends within 0.12 of
    // its extent at some grid resolutions, and won the vote as up = −z). A quadruped stands
    // 0.5–0.6 of its length tall (wolf0 0.53).
    // A limb end counts as on the ground as in step 4 (below ground_band and within ground_step of
    // the lowest end), and a tie goes to the end the solid stands on more broadly (solid cells in
    // its lowest 3 %): the Stanford armadillo's two ear tips and raised hand lie as low along −y as
    // its two feet along +y (3 ends to 2 by the band alone, and it was fitted upside down; 111 % bone
    // disagreement), but its soles are flat.
    const Eigen::Vector3d extent = (Vt.colwise().maxCoeff() - Vt.colwise().minCoeff()).transpose();
    const Eigen::MatrixXd cells = jf_solid_samples(TS.volume, 20000);
    int best = -1, best_support = -1;
    for (int a : {1, 2, 0, 4, 5, 3}) {
      if (extent[a % 3] < opt.min_up_extent * extent.maxCoeff()) continue;
      const JfFrame f = jf_frame(Vt, jf_axis(a));
      double lowest = std::numeric_limits<double>::infinity();
      for (int i = 0; i < Lt.rows(); ++i) lowest = std::min(lowest, f.height(Lt.row(i).transpose()));
      int n = 0;
      for (int i = 0; i < Lt.rows(); ++i) {
        const double h = f.height(Lt.row(i).transpose());
        n += h < opt.ground_band && h <= lowest + opt.ground_step;
      }
      if (n < best) continue;
      int support = 0;
      for (int i = 0; i < cells.rows(); ++i) support += f.height(cells.row(i).transpose()) < 0.03;
      if (n > best || support > best_support) best = n, best_support = support, up_t = a;
    }
  }
  r.target_up = up_t;
  const Eigen::Vector3d ut = jf_axis(up_t);

  // 3–4. Facing: 4 turns about up, scored by chamfer of the solids + limb-end matching.
  if (!progress.update("fitting", 0.9)) return fail(StatusCode::Cancelled, "cancelled during fitting");
  const JfFrame fs = jf_frame(Vs, us);
  const Eigen::MatrixXd Ps = jf_solid_samples(SS.volume, 1200), Pt = jf_solid_samples(TS.volume, 1200);
  Eigen::MatrixXd Ps_n(Ps.rows(), 3);
  for (int i = 0; i < Ps.rows(); ++i) Ps_n.row(i) = fs(Ps.row(i).transpose()).transpose();
  // Limb-end descriptors: the end and the point back_length × height up its path toward the
  // root (elbow/knee-ish), so that an A-pose and a T-pose still pair hands with hands.
  // The walk back stops at half the limb (to its first branch point): a short, chibi arm
  // (KayKit) must not reach past its shoulder while a long one stops at the elbow, and a bump
  // (her shoulder) stays at its tip. Measured: KayKit Knight's bones in human_woman 13.2% →
  // 10.2% of the height (the left hand no longer goes to the bump); no other fit changed.
  auto back_point = [&](const JfTree& tree, int leaf, double length) {
    double limb = 0;
    for (int a = leaf; tree.s->parent[a] >= 0; a = tree.s->parent[a]) {
      limb += (tree.pos(tree.s->parent[a]) - tree.pos(a)).norm();
      if (tree.children[tree.s->parent[a]] >= 2) break;
    }
    length = std::min(length, opt.back_limb_fraction * limb);
    int a = leaf;
    double arc = 0;
    while (tree.s->parent[a] >= 0 && arc < length) {
      arc += (tree.pos(tree.s->parent[a]) - tree.pos(a)).norm();
      a = tree.s->parent[a];
    }
    return tree.pos(a);
  };
  std::vector<Eigen::Vector3d> Sn;
  for (int i = 0; i < Ls.rows(); ++i) {
    Sn.push_back(fs(Ls.row(i).transpose()));
    Sn.push_back(fs(back_point(st, s_leaves[i], opt.back_length * fs.H)));
  }
  double best_cost = std::numeric_limits<double>::infinity();
  JfLeafMatch match;
  JfFrame ft;
  for (const Eigen::Matrix3d& R : jf_rotations()) {
    if ((R * ut - us).norm() > 1e-9) continue;
    if (opt.target_front >= 0 && (R * jf_axis(opt.target_front) - jf_axis(opt.source_front)).norm() > 1e-9) continue;
    const Eigen::MatrixXd Vr = Vt * R.transpose();
    const JfFrame f = jf_frame(Vr, us);
    Eigen::MatrixXd Pt_n(Pt.rows(), 3);
    for (int i = 0; i < Pt.rows(); ++i) Pt_n.row(i) = f(R * Pt.row(i).transpose()).transpose();
    std::vector<Eigen::Vector3d> Tn;
    for (int i = 0; i < Lt.rows(); ++i) {
      Tn.push_back(f(R * Lt.row(i).transpose()));
      Tn.push_back(f(R * back_point(tt, t_leaves[i], opt.back_length * f.H)));
    }
    JfLeafMatch m = jf_match_leaves(Sn, s_leaves, Tn, t_leaves, opt.leaf_tolerance);
    // An unmatched limb end on either side costs the tolerance: a turn that leaves the head of
    // both unmatched (a quadruped turned back to front: its legs still pair) loses to one that
    // pairs them.
    const double unmatched_t = double(t_leaves.size() - std::min(t_leaves.size(), m.pairs.size()));
    const double cost = jf_chamfer(Ps_n, Pt_n) + (m.cost + opt.leaf_tolerance * unmatched_t) / double(s_leaves.size() + t_leaves.size());
    if (cost < best_cost) best_cost = cost, match = m, r.rotation = R, ft = f;
  }
  const Eigen::Matrix3d R = r.rotation;
  r.limb_ends = match.pairs;
  // Limbs on the ground: ground limb ends grouped when their paths meet low (the corners of one
  // blocky boot meet inside the foot; two feet meet at the crotch or the body).
  // A limb end also has to be within ground_step of the lowest one: RobotExpressive's hands hang
  // to 0.07 and 0.13 of its height, its feet end at 0.014 (feet of every character in the tests:
  // 0–0.016).
  auto ground_limbs = [&](const JfTree& tree, const std::vector<int>& leaves, const std::function<double(int)>& height) {
    double lowest = std::numeric_limits<double>::infinity();
    for (int l : leaves) lowest = std::min(lowest, height(l));
    std::vector<int> g;
    for (int l : leaves)
      if (height(l) < opt.ground_band && height(l) <= lowest + opt.ground_step) g.push_back(l);
    std::vector<int> group(g.size());
    for (size_t i = 0; i < g.size(); ++i) group[i] = int(i);
    for (size_t i = 0; i < g.size(); ++i)
      for (size_t j = i + 1; j < g.size(); ++j)
        if (height(tree.lca(g[i], g[j])) < opt.ground_band) {
          const int a = group[i], b = group[j];
          for (int& x : group)
            if (x == b) x = a;
        }
    std::sort(group.begin(), group.end());
    return int(std::unique(group.begin(), group.end()) - group.begin());
  };
  r.source_ground = ground_limbs(st, s_leaves, [&](int n) { return fs.height(st.pos(n)); });
  r.target_ground = ground_limbs(tt, t_leaves, [&](int n) { return ft.height(R * tt.pos(n)); });

  // Closest points of the used source joints on the whole source skeleton, to find which limb
  // ends carry joints (an edge (u, parent u) whose subtree below holds a single leaf is that leaf's).
  int ns = SS.size();  // changes when touching legs are split (step 4b)
  std::vector<int> leaves_below(ns, 0), only_leaf(ns, -1);
  {
    std::vector<int> order(ns);
    for (int i = 0; i < ns; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return st.depth[a] > st.depth[b]; });
    const auto adj = SS.adjacency();
    for (int i : order) {
      if (adj[i].size() == 1 && i != SS.root) leaves_below[i] += 1;
      if (SS.parent[i] >= 0) leaves_below[SS.parent[i]] += leaves_below[i];
    }
    for (int i = 0; i < ns; ++i)
      if (adj[i].size() == 1 && i != SS.root)
        for (int x = i; x >= 0 && leaves_below[x] == 1; x = SS.parent[x]) only_leaf[x] = i;
  }
  auto closest_on_edges = [&](const Eigen::Vector3d& p, const std::vector<int>& edges, int* edge, double* t) {
    double best = std::numeric_limits<double>::infinity();
    Eigen::Vector3d q = st.pos(SS.root);
    *edge = -1, *t = 0;
    for (int u : edges) {
      const Eigen::Vector3d a = st.pos(u), b = st.pos(SS.parent[u]);
      const double l2 = (b - a).squaredNorm();
      const double x = l2 > 0 ? std::clamp((p - a).dot(b - a) / l2, 0.0, 1.0) : 0.0;
      const Eigen::Vector3d c = a + x * (b - a);
      const double d = (p - c).squaredNorm();
      if (d < best) best = d, q = c, *edge = u, *t = x;
    }
    return q;
  };
  std::vector<int> all_edges;
  for (int i = 0; i < ns; ++i)
    if (SS.parent[i] >= 0) all_edges.push_back(i);
  std::map<int, std::vector<std::string>> joints_on_leaf;
  for (int j : used) {
    int e;
    double t;
    closest_on_edges(source_joints.P.row(j).transpose(), all_edges, &e, &t);
    if (e >= 0 && only_leaf[e] >= 0) joints_on_leaf[only_leaf[e]].push_back(source_joints.names[j]);
  }
  // 4, second pass: limbs that carry joints and found no partner by position, paired by where
  // they join the body.
  if (opt.match_by_attachment) {
    std::vector<uint8_t> s_taken(ns, 0), t_taken(TS.size(), 0);
    for (const auto& pr : match.pairs) s_taken[pr.first] = 1, t_taken[pr.second] = 1;
    std::vector<int> s_free, t_free;
    for (const auto& [leaf, names] : joints_on_leaf)
      if (!s_taken[leaf] && names.size() >= 2) s_free.push_back(leaf);
    for (int l : t_leaves)
      if (!t_taken[l]) t_free.push_back(l);
    const std::vector<int> paired = jf_match_by_attachment(
        st, tt, s_free, t_free, &match, [&](const Eigen::Vector3d& p) { return fs(p); },
        [&](const Eigen::Vector3d& p) { return ft(R * p); }, opt.leaf_tolerance);
    if (!paired.empty()) {
      r.limb_ends = match.pairs;
      std::vector<std::string> ends;
      for (int l : paired) ends.push_back(joints_on_leaf[l].back());
      r.warnings.push_back("the source's limbs ending at " + jf_join(ends) +
                           " are posed unlike the target's (e.g. hanging arms against a T-pose): they were paired by "
                           "where they join the body; check those joints");
    }
  }
  std::map<int, int> matched_s;  // source leaf node → index in match.pairs
  for (size_t k = 0; k < match.pairs.size(); ++k) matched_s[match.pairs[k].first] = int(k);
  if (opt.check_topology) {
    std::vector<std::string> lost, pinned_lost;
    // An unmatched end carrying joints is lost unless it is a sub-branch of a matched limb
    // (another finger of a matched hand): path length to a matched end < back_length × height.
    // A lost limb with a joint pinned by a marker, or within marker_reach bones of one (the joints
    // step 6 moves, jf_hops), is not refused (the refusal asks for markers): its joints are placed
    // on the matched limbs and follow the markers.
    std::vector<int> marked;
    std::vector<uint8_t> is_marked(source_joints.size(), 0);
    for (const JointMarker& m : markers)
      if (const int k = source_joints.find(m.name); k >= 0 && !is_marked[k]) is_marked[k] = 1, marked.push_back(k);
    const bool has_tree = static_cast<int>(source_joints.parent.size()) == source_joints.size();
    const std::vector<int> hops = jf_hops(jf_bone_adjacency(has_tree ? source_joints.parent : std::vector<int>(source_joints.size(), -1)),
                                          marked, opt.marker_reach, is_marked);
    for (const auto& [leaf, names] : joints_on_leaf) {
      if (matched_s.count(leaf) || names.size() < 2) continue;
      double nearest = std::numeric_limits<double>::infinity();
      for (const auto& pr : match.pairs) {
        const int l = st.lca(leaf, pr.first);
        const double d = (st.pos(leaf) - st.pos(l)).norm() + (st.pos(pr.first) - st.pos(l)).norm();
        nearest = std::min(nearest, d);
      }
      if (nearest <= opt.back_length * fs.H) continue;
      const bool pinned = std::any_of(names.begin(), names.end(), [&](const std::string& n) {
        const int k = source_joints.find(n);
        return k >= 0 && hops[k] >= 0;
      });
      (pinned && markers_lift_lost ? pinned_lost : lost).push_back(names.back());
    }
    if (lost.empty() && !pinned_lost.empty())
      r.warnings.push_back("no limb of the target matches the source's chain ending at " + jf_join(pinned_lost) +
                           ": its joints were placed from your markers; check them");
    const std::string counts = "the source has " + std::to_string(s_leaves.size()) + " limb ends (" +
                               std::to_string(r.source_ground) + " on the ground), the target " +
                               std::to_string(t_leaves.size()) + " (" + std::to_string(r.target_ground) +
                               " on the ground, up " + jf_axis_name(up_t) + ")";
    if (std::abs(r.source_ground - r.target_ground) >= 2)
      return fail(StatusCode::InvalidArgument,
                  "topology mismatch: the source skeleton stands on " + std::to_string(r.source_ground) +
                      " limbs and the target on " + std::to_string(r.target_ground) +
                      " (e.g. a biped skeleton on a quadruped); " + counts +
                      ". Use a source character of the target's kind, or give the target's up axis (--target-up) "
                      "if it was detected wrongly");
    if (!lost.empty()) {
      if (lost_limbs) *lost_limbs = true;
      return fail(StatusCode::InvalidArgument,
                  "topology mismatch: no limb of the target matches the source's chain ending at " + jf_join(lost) +
                      "; " + counts + ". Use a source of the target's kind, pin those joints with markers" +
                      (opt.source_skeleton == SourceSkeleton::Voxel
                           ? ", or fit the source's own bones (source_skeleton bones: for blocky, many-part sources)"
                           : ""));
    }
  }
  if (match.pairs.size() < 2)
    return fail(StatusCode::InvalidArgument, "fewer than 2 limb ends of the target match the source's: place the joints with markers");

  // 4b. Touching legs: a biped whose skeleton forks below its crotch. Both curve skeletons are
  // cut alike (a self-fit stays exact); the source's own bones have a real hip joint.
  if (r.source_ground == 2 && r.target_ground == 2 && opt.touching_legs_groove > 0) {
    std::vector<std::pair<int, int>> feet;
    int top = -1;
    double top_height = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < int(match.pairs.size()); ++i) {
      const auto& pr = match.pairs[i];
      const double ht = ft.height(R * tt.pos(pr.second));
      if (fs.height(st.pos(pr.first)) < opt.ground_band && ht < opt.ground_band) feet.push_back(pr);
      if (ht > top_height) top_height = ht, top = i;
    }
    if (feet.size() == 2 && top >= 0) {
      const std::pair<int, int> head = match.pairs[top];
      const std::vector<int> remap_t = jf_split_touching_legs(&r.target_skeleton, tt, {feet[0].second, feet[1].second},
                                                              head.second, ut, opt.touching_legs_groove);
      const std::vector<int> remap_s =
          source_is_curve ? jf_split_touching_legs(&r.source_skeleton, st, {feet[0].first, feet[1].first}, head.first, us,
                                                   opt.touching_legs_groove)
                          : std::vector<int>{};
      if (!remap_t.empty()) {
        tt = JfTree(TS);
        for (auto& pr : match.pairs) pr.second = remap_t[pr.second];
        r.warnings.push_back("the target's thighs touch (its skeleton forked below the crotch): the legs were split "
                             "up to the crotch");
      }
      if (!remap_s.empty()) {
        st = JfTree(SS);
        ns = SS.size();
        for (auto& pr : match.pairs) pr.first = remap_s[pr.first];
      }
      r.limb_ends = match.pairs;
    }
  }

  // 5. Paths between matched ends on both sides, and their branch points.
  const int nm = int(match.pairs.size());
  struct PairPaths {
    int a, b;
    JfPath ps, pt;
  };
  std::vector<PairPaths> pairs;
  std::vector<uint8_t> on_matched(ns, 0);
  for (int a = 0; a < nm; ++a)
    for (int b = a + 1; b < nm; ++b) {
      PairPaths pp{a, b, jf_path(st, match.pairs[a].first, match.pairs[b].first),
                   jf_path(tt, match.pairs[a].second, match.pairs[b].second)};
      for (size_t i = 0; i + 1 < pp.ps.nodes.size(); ++i) {
        const int x = pp.ps.nodes[i], y = pp.ps.nodes[i + 1];
        on_matched[SS.parent[x] == y ? x : y] = 1;
      }
      pairs.push_back(std::move(pp));
    }
  std::vector<int> matched_edges;
  for (int i = 0; i < ns; ++i)
    if (on_matched[i] && SS.parent[i] >= 0) matched_edges.push_back(i);
  // Arc position of a branch label on a path: −1 = the path's start, −2 = its end, c = median with end c.
  auto label_arc = [&](const JfTree& tree, const JfPath& p, int a, int b, int c, bool source_side) {
    if (c == -1) return 0.0;
    if (c == -2) return p.length();
    const auto& mp = match.pairs;
    const int m = source_side ? tree.median(mp[a].first, mp[b].first, mp[c].first)
                              : tree.median(mp[a].second, mp[b].second, mp[c].second);
    const int i = p.index_of(m);
    return i >= 0 ? p.arc[i] : 0.0;
  };

  JointSet& out = r.joints;
  std::vector<int> out_index(source_joints.size(), -1);
  std::vector<std::string> outside;
  // Arc length along a source path of the point at fraction t of edge (e, parent e), or −1 when the
  // path does not hold that edge.
  auto arc_on_source = [&](const JfPath& ps, int e, double t) {
    for (size_t k = 0; k + 1 < ps.nodes.size(); ++k)
      if ((ps.nodes[k] == e && ps.nodes[k + 1] == SS.parent[e]) || (ps.nodes[k + 1] == e && ps.nodes[k] == SS.parent[e]))
        return ps.arc[k] + (ps.nodes[k] == e ? t : 1 - t) * (ps.arc[k + 1] - ps.arc[k]);
    return -1.0;
  };
  // Markers as anchors along the paths (proportions along branches re-measured from them): a
  // marked joint's closest point on the source path and the marker's closest point on the target
  // path (when the marker lies within marker_anchor × height of it) are one more pair of
  // corresponding positions beside the branch points, so the joints of a marked chain are spread
  // between the marker and its neighbouring branch points, not only dragged toward it (step 6).
  struct MarkerAnchor {
    int e;
    double t;
    Eigen::Vector3d m;
  };
  std::vector<MarkerAnchor> anchors;
  if (opt.marker_anchor > 0)
    for (const JointMarker& mk : markers) {
      const int k = source_joints.find(mk.name);
      if (k < 0 || !mk.position.allFinite()) continue;  // step 6 reports it
      MarkerAnchor a{-1, 0, mk.position};
      closest_on_edges(source_joints.P.row(k).transpose(), matched_edges, &a.e, &a.t);
      if (a.e >= 0) anchors.push_back(a);
    }
  // The closest point to m on a target path: its distance, arc length and position.
  struct OnPath {
    double distance = std::numeric_limits<double>::infinity(), arc = -1;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
  };
  // Only the part of the path between arc lengths lo and hi when given.
  auto closest_on_target_path = [&](const JfPath& pt, const Eigen::Vector3d& m, double lo = -1.0,
                                    double hi = std::numeric_limits<double>::infinity()) {
    OnPath best;
    for (size_t k = 0; k + 1 < pt.nodes.size(); ++k) {
      const double a0 = pt.arc[k], a1 = pt.arc[k + 1];
      if (a1 < lo || a0 > hi) continue;
      const double u0 = a1 > a0 ? std::max(0.0, (lo - a0) / (a1 - a0)) : 0.0;
      const double u1 = a1 > a0 ? std::min(1.0, (hi - a0) / (a1 - a0)) : 1.0;
      const Eigen::Vector3d x = tt.pos(pt.nodes[k]), y = tt.pos(pt.nodes[k + 1]);
      const double l2 = (y - x).squaredNorm();
      const double u = l2 > 0 ? std::clamp((m - x).dot(y - x) / l2, u0, std::max(u0, u1)) : 0.0;
      const double d = (m - x - u * (y - x)).norm();
      if (d < best.distance) best = {d, pt.arc[k] + u * (pt.arc[k + 1] - pt.arc[k]), x + u * (y - x)};
    }
    return best;
  };
  auto arc_on_target = [&](const JfPath& pt, const Eigen::Vector3d& m) {
    const OnPath c = closest_on_target_path(pt, m);
    return c.distance <= opt.marker_anchor * ft.H ? c.arc : -1.0;  // ft.H: the target's height
  };
  // Per pair of matched ends: (source arc, target arc) of its branch points and marker anchors, by
  // source arc, target arcs increasing (an anchor out of order with them is left out).
  std::vector<std::vector<std::pair<double, double>>> breaks(pairs.size());
  for (size_t ip = 0; ip < pairs.size(); ++ip) {
    const PairPaths& pp = pairs[ip];
    // Branch points grouped by position along the source path; a group's target arc is the mean.
    std::vector<std::pair<double, std::vector<int>>> groups;
    std::vector<int> labels = {-1, -2};
    for (int c = 0; c < nm; ++c)
      if (c != pp.a && c != pp.b) labels.push_back(c);
    for (int c : labels) {
      const double x = label_arc(st, pp.ps, pp.a, pp.b, c, true);
      auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return std::abs(g.first - x) < 1e-12; });
      if (it == groups.end()) groups.push_back({x, {c}});
      else it->second.push_back(c);
    }
    std::stable_sort(groups.begin(), groups.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    std::vector<std::pair<double, double>>& b = breaks[ip];
    for (const auto& g : groups) {
      double x = 0;
      for (int c : g.second) x += label_arc(tt, pp.pt, pp.a, pp.b, c, false);
      b.push_back({g.first, x / g.second.size()});
    }
    for (const MarkerAnchor& a : anchors) {
      const double s = arc_on_source(pp.ps, a.e, a.t);
      const double x = s >= 0 ? arc_on_target(pp.pt, a.m) : -1.0;
      if (x < 0) continue;
      const auto at = std::upper_bound(b.begin(), b.end(), s, [](double v, const auto& g) { return v < g.first; });
      if (at == b.begin() || at == b.end() || !(std::prev(at)->first < s) || !(std::prev(at)->second < x) || !(x < at->second)) continue;
      b.insert(at, {s, x});
    }
  }
  // Each joint's target skeleton point and offset first (placed below).
  struct Carried {
    bool ok = false;
    Eigen::Vector3d qt, off;  // target skeleton point; offset in the target's axes, scaled
    double far = 1;           // the offset's length in source radii at its skeleton point
    struct Span {
      int pair;
      double lo, hi;
    };
    std::vector<Span> spans;  // the stretches of matched target paths (between branch points) qt was taken from
  };
  std::vector<Carried> carried(source_joints.size());
  for (int j : used) {
    const Eigen::Vector3d pj = source_joints.P.row(j).transpose();
    int e;
    double t;
    const Eigen::Vector3d q = closest_on_edges(pj, matched_edges, &e, &t);
    const double rq = (1 - t) * SS.radius[e] + t * SS.radius[SS.parent[e]];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double rsum = 0;
    int n = 0;
    for (size_t ip = 0; ip < pairs.size(); ++ip) {
      const PairPaths& pp = pairs[ip];
      const double s = arc_on_source(pp.ps, e, t);  // q along this source path, if it holds edge e
      if (s < 0) continue;
      const std::vector<std::pair<double, double>>& b = breaks[ip];
      size_t k = 0;
      while (k + 2 < b.size() && b[k + 1].first <= s) ++k;
      const double span = b[k + 1].first - b[k].first;
      const double tau = span > 0 ? std::clamp((s - b[k].first) / span, 0.0, 1.0) : 0.0;
      const double lo = b[k].second, hi = b[k + 1].second;
      Eigen::Vector3d x;
      double rx;
      jf_point_at(tt, pp.pt, lo + tau * (hi - lo), &x, &rx);
      sum += x, rsum += rx, ++n;
      carried[j].spans.push_back({static_cast<int>(ip), lo, hi});
    }
    if (n == 0) continue;  // cannot happen: e lies on some matched path
    const Eigen::Vector3d qt = sum / n;
    const double rt = rsum / n;
    // The radii's ratio, clamped relative to the heights' ratio: the two files may use any units (a
    // Fox ~100 units tall, Sumner's cat 0.38), and the clamp bounds how much thicker or thinner the
    // target's limb may be than the source's once both are the same height.
    const double hs = ft.H / fs.H;
    const double scale = hs * std::clamp(rq > 0 ? rt / (rq * hs) : 1.0, 0.25, 4.0);
    carried[j].ok = true;
    carried[j].qt = qt;
    carried[j].off = R.transpose() * (pj - q) * scale;
    carried[j].far = rq > 0 ? (pj - q).norm() / rq : 1.0;
  }
  // Offsets far from the skeleton. A joint several radii from its skeleton point (a robot's
  // shoulder: 5.4 radii from its hanging arm's path) is not described by that point: carried in
  // fixed axes onto a limb posed otherwise (CesiumMan's spread arm), its offset leads anywhere (into
  // his head, which is inside the mesh, so step 6 keeps it). Such offsets are capped at
  // offset_cap radii, unless the target is of the source's rig family — the fitted skeleton then
  // agrees with the source's bones as in step 5c (Σ|d − b| / Σ|b| ≤ 1.6 × skeleton_prior_agreement
  // over bones between placed joints), where offsets carry over as they are (self fits stay exact;
  // KayKit's IK helpers lie 9.5 radii off the feet).
  // The source's bone (child c, parent p) carried into the target's frame by the global similarity.
  auto source_bone = [&](int c, int p) -> Eigen::Vector3d {
    return R.transpose() * ((ft.H / fs.H) * (source_joints.P.row(c) - source_joints.P.row(p)).transpose());
  };
  if (opt.offset_cap > 0) {
    BoneAgreement agreement;
    for (int j : used) {
      if (!carried[j].ok) continue;
      int a = static_cast<int>(source_joints.parent.size()) == source_joints.size() ? source_joints.parent[j] : -1;
      while (a >= 0 && !carried[a].ok) a = source_joints.parent[a];
      if (a < 0) continue;
      agreement.add((carried[j].qt + carried[j].off) - (carried[a].qt + carried[a].off), source_bone(j, a));
    }
    if (agreement.ratio() > 1.6 * opt.skeleton_prior_agreement)
      for (int j : used)
        if (carried[j].ok && carried[j].far > opt.offset_cap) carried[j].off *= opt.offset_cap / carried[j].far;
  }
  for (int j : used) {
    if (!carried[j].ok) continue;
    const Eigen::Vector3d qt = carried[j].qt, off = carried[j].off;
    // 6. Pull toward the skeleton point until inside.
    Eigen::Vector3d p = qt + off;
    if (!inside_t(p)) {
      // Outside: pulled toward the nearest point of the stretch of skeleton (between branch
      // points) qt was taken from first, which keeps the joint at the height its offset gave it
      // (the robot's hip joint, carried out of CesiumMan's thigh: 7.1 → 4.1 % of the height), then
      // toward qt as before. (The nearest point of the whole skeleton can be another part's: the
      // robot's Shoulder.L went into CesiumMan's neck.)
      OnPath c;
      for (const Carried::Span& sp : carried[j].spans) {
        const OnPath x = closest_on_target_path(pairs[sp.pair].pt, p, std::min(sp.lo, sp.hi), std::max(sp.lo, sp.hi));
        if (x.distance < c.distance) c = x;
      }
      const Eigen::Vector3d p0 = p;
      for (int it = 0; it < 6 && !inside_t(p) && c.arc >= 0; ++it) p = c.point + (p0 - c.point) * std::pow(0.5, it + 1);
    }
    for (int it = 0; it < 6 && !inside_t(p); ++it) p = qt + off * std::pow(0.5, it + 1);
    if (!inside_t(p)) p = qt;
    if (!inside_t(p)) {
      // Between parts (a robot's gap at a knee): just inside the nearest surface.
      const ClosestPoint c = bvh_t.closest_point(p);
      if (c.face >= 0) {
        const Eigen::Vector3d a = Vt.row(Ft(c.face, 0)), b = Vt.row(Ft(c.face, 1)), d = Vt.row(Ft(c.face, 2));
        const Eigen::Vector3d n = (b - a).cross(d - a).normalized();
        for (double side : {1.0, -1.0}) {
          const Eigen::Vector3d x = c.point - side * 0.5 * tol_t * n;
          if (n.allFinite() && bvh_t.inside(x)) {
            p = x;
            break;
          }
        }
      }
    }
    if (!inside_t(p)) outside.push_back(source_joints.names[j]);
    out_index[j] = out.size();
    out.names.push_back(source_joints.names[j]);
    out.P.conservativeResize(out.size(), 3);
    out.P.row(out.size() - 1) = p.transpose();
  }
  // Hierarchy: nearest placed ancestor.
  for (int j : used) {
    if (out_index[j] < 0) continue;
    int p = static_cast<int>(source_joints.parent.size()) == source_joints.size() ? source_joints.parent[j] : -1;
    while (p >= 0 && out_index[p] < 0) p = source_joints.parent[p];
    out.parent.push_back(p >= 0 ? out_index[p] : -1);
  }

  // 5b. Refinement by the surfaces around the joints (jf_refine_by_surface); joints step 6 could
  // not bring inside are left where they are.
  if (opt.surface_refine_iterations > 0) {
    Eigen::MatrixXd Js(out.size(), 3);
    for (int j : used)
      if (out_index[j] >= 0) Js.row(out_index[j]) = source_joints.P.row(j);
    const auto to_target = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d { return R.transpose() * (ft.o + ft.H * fs(p)); };
    const std::vector<uint8_t> was_outside = [&] {
      std::vector<uint8_t> v(out.size(), 0);
      for (const std::string& nm : outside) v[out.find(nm)] = 1;
      return v;
    }();
    JointSet refined = out;
    jf_refine_by_surface(Vs, in.Fs, Js, to_target, in.bvh_s, bvh_t, inside_t,
                         opt.surface_refine_seen && !r.source_skeleton.volume.solid.empty() ? &r.source_skeleton.volume : nullptr, fs.H, opt, &refined);
    for (int k = 0; k < out.size(); ++k) {
      if (was_outside[k]) continue;
      const Eigen::Vector3d p0 = out.P.row(k).transpose(), d = refined.P.row(k).transpose() - p0;
      const double limit = opt.surface_refine_max_move * std::max(std::sqrt(bvh_t.closest_point(p0).sq_distance), 0.01 * ft.H);
      const Eigen::Vector3d p = d.norm() > limit ? Eigen::Vector3d(p0 + d * (limit / d.norm())) : Eigen::Vector3d(p0 + d);
      if (inside_t(p)) out.P.row(k) = p.transpose();
    }
  }

  // The source joint of each placed joint (steps 5c and the crossing check below).
  std::vector<int> src_of(out.size(), -1);
  for (int j : used)
    if (out_index[j] >= 0) src_of[out_index[j]] = j;

  // 5c. Skeleton prior: every bone of the fit pulled toward the source's bone carried by the
  // global similarity (b = R (H_t/H_s) (s_c − s_p)), least squares against the fitted positions:
  //   min Σ_j |p_j − p̂_j|² + w Σ_(c,p) |(p_c − p_p) − b_cp|²
  // (the proportions-and-directions term of skeleton embedding, Baran & Popović 2007). Trusted
  // only where the fit already agrees with the source's skeleton: with r = Σ|d − b| / Σ|b| over
  // the fitted bones d, w is full for r ≤ a (skeleton_prior_agreement), fades linearly to 0 at
  // 1.6 a. Same-rig pairs (KayKit Knight/Barbarian) measure r 0.11–0.13; a fox's skeleton in a
  // wolf 0.27, CesiumMan's in a woman 0.37, in michael3 0.32 — there the source's proportions
  // would pull joints off the target's anatomy. A self fit is unchanged (r = 0, p̂ = source).
  if (opt.skeleton_prior > 0 && out.size() > 1) {
    const int n = out.size();
    std::vector<std::pair<int, Eigen::Vector3d>> bones;  // (child k, source bone in target frame)
    BoneAgreement agreement;
    for (int k = 0; k < n; ++k) {
      const int q = out.parent[k];
      if (q < 0) continue;
      const Eigen::Vector3d b = source_bone(src_of[k], src_of[q]);
      agreement.add((out.P.row(k) - out.P.row(q)).transpose(), b);
      bones.emplace_back(k, b);
    }
    const double a = opt.skeleton_prior_agreement, rel = agreement.ratio();
    r.skeleton_agreement = rel;
    // Fits of one kind of character measure r 0.11–0.45 (above; CesiumMan in human_woman at 72–192
    // cells, 3.3–4.9 %: 0.33–0.45). Her broken fits (48 and 64 cells, 21 %) measure 0.40 since the
    // grid is centred (forty-fifth session; 0.53–0.62 before), so r does not tell them: the check
    // for limbs that cross the body's middle (below) does.
    if (rel > 0.5) {
      char note[240];
      std::snprintf(note, sizeof note,
                    "the fitted bones differ from the source's by %.0f %% (good fits of one kind of character: at most "
                    "~45 %%): check the joints, pin a few with markers, or try another skeleton resolution",
                    100 * rel);
      r.warnings.push_back(note);
    }
    const double gate = a > 0 ? std::clamp((1.6 * a - rel) / (0.6 * a), 0.0, 1.0) : (rel <= 0 ? 1.0 : 0.0);
    const double w = opt.skeleton_prior * gate;
    r.skeleton_prior_used = w;
    if (w > 0 && rel > 1e-9) {
      char note[200];
      std::snprintf(note, sizeof note,
                    "the source's skeleton was used as a prior (weight %.2g): the fitted bones differ from the source's by %.0f %%, "
                    "as within one rig family (option skeleton_prior 0 turns this off)",
                    w, 100 * rel);
      r.warnings.push_back(note);
    }
    if (w > 0) {
      Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n), B = out.P;
      for (const auto& [k, b] : bones) {
        const int q = out.parent[k];
        A(k, k) += w, A(q, q) += w, A(k, q) -= w, A(q, k) -= w;
        B.row(k) += w * b.transpose();
        B.row(q) -= w * b.transpose();
      }
      const Eigen::MatrixXd P = A.ldlt().solve(B);
      for (int k = 0; k < n; ++k)
        if (P.row(k).allFinite() && inside_t(P.row(k).transpose()) &&
            std::find(outside.begin(), outside.end(), out.names[k]) == outside.end())
          out.P.row(k) = P.row(k);
    }
  }

  // 5d. Ball joints. A target built of separate parts bends where its small round parts sit (the
  // robot's hips, elbows, neck and ankles are the centres of such balls; its true hip and elbow
  // joints lie 0.016 and 0.002 of its height from them). A fitted joint and a ball that are each
  // other's nearest, within ball_joint_reach radii, make a pair: the joint moves to the ball's
  // centre, plus its source joint's offset from the source's own ball (carried into the target's
  // axes and scale) where the source's joint has one — a self fit of the robot stays exact, and a
  // rig that keeps a joint off its ball keeps it off the target's. Fits onto single-part meshes
  // are unchanged (no balls).
  if (opt.ball_joint_reach > 0 && !in.balls_t.empty()) {
    Eigen::MatrixXd Pt = out.P;
    for (const std::string& nm : outside) Pt.row(out.find(nm)).setConstant(std::numeric_limits<double>::quiet_NaN());
    const std::vector<int> t_pair = pair_balls_with_joints(in.balls_t, Pt, out.parent, opt.ball_joint_reach);
    std::vector<int> s_ball(source_joints.size(), -1);
    if (!in.balls_s.empty()) {
      // The placed joints in the source, with the placed joints' hierarchy.
      Eigen::MatrixXd Ps(out.size(), 3);
      for (int k = 0; k < out.size(); ++k) Ps.row(k) = source_joints.P.row(src_of[k]);
      const std::vector<int> s_pair = pair_balls_with_joints(in.balls_s, Ps, out.parent, opt.ball_joint_reach);
      for (size_t b = 0; b < s_pair.size(); ++b)
        if (s_pair[b] >= 0) s_ball[src_of[s_pair[b]]] = int(b);
    }
    for (size_t b = 0; b < t_pair.size(); ++b) {
      const int k = t_pair[b];
      if (k < 0 || src_of[k] < 0) continue;
      Eigen::Vector3d p = in.balls_t[b].centre;
      if (const int sb = s_ball[src_of[k]]; sb >= 0)
        p += R.transpose() * (source_joints.P.row(src_of[k]).transpose() - in.balls_s[sb].centre) * (ft.H / fs.H);
      if (!inside_t(p)) continue;
      out.P.row(k) = p.transpose();
      r.ball_joints.push_back(out.names[k]);
    }
    if (!r.ball_joints.empty())
      r.warnings.push_back(std::to_string(r.ball_joints.size()) + " joint" + (r.ball_joints.size() > 1 ? "s" : "") +
                           " moved to the centre of the target's ball parts (" + jf_join(r.ball_joints, 8) +
                           "; option ball_joint_reach 0 turns this off)");
  }

  // 5e. Places across the body. A rig puts a joint at some place in the body's section through it: a
  // knee near the front of the leg, a hip joint behind the groin, a root on the middle of the
  // pelvis. The offsets of step 5 carry that from the source's skeleton, not from its surface, and a
  // voxel skeleton's branch points can lie off the middle (RobotExpressive's legs fork 0.02 of its
  // height to the side of its middle and 0.05 behind: CesiumMan's root went there). Two moves, from
  // the rays ±axis through the source joint to where they leave the body (b_s behind, f_s ahead)
  // and through the fitted joint p (b_t, f_t): depths across limbs (front axis) and middle joints
  // (side axis), below. Not for a target of the source's rig family (step 5c's prior has placed
  // it) nor at ball joints.
  // The two middle planes (here, step 5f and the crossing check below): normal to up × front,
  // through the centres of the bounding boxes.
  const Eigen::Vector3d side = us.cross(jf_axis(opt.source_front));
  const Eigen::Vector3d mid_s = 0.5 * (Vs.colwise().minCoeff() + Vs.colwise().maxCoeff()).transpose();
  const Eigen::Vector3d mid_t = 0.5 * (Vt.colwise().minCoeff() + Vt.colwise().maxCoeff()).transpose();
  const double es = 1e-3 * fs.H, et = 1e-3 * ft.H;
  auto kept_in_place = [&](int k) {
    return std::find(outside.begin(), outside.end(), out.names[k]) != outside.end() ||
           std::find(r.ball_joints.begin(), r.ball_joints.end(), out.names[k]) != r.ball_joints.end();
  };
  // Whether the two sections, scaled by the heights, are within max_ratio of each other.
  auto spans_agree = [&](double bs, double fs_, double bt, double ft_, double max_ratio) {
    const double ratio = (bt + ft_) / ((bs + fs_) * ft.H / fs.H);
    return ratio * max_ratio > 1 && ratio < max_ratio;
  };
  // Depths across a limb seen from the front: p moves along front to the source joint's fraction
  // of the depth, p ← p + (−b_t + b_s / (b_s + f_s) · (b_t + f_t)) · front_t. Only where front is
  // neither the longest of the source joint's three spans (a quadruped's body) nor within 60° of
  // the source's bone at the joint (the fitted bones are the fit's own guess: CesiumMan's root,
  // placed behind the robot's spine, tilted its fitted spine bone toward front, which kept the root
  // there); both rays leave the body at their first hit (a many-part robot's rays end on inner
  // parts); the depths agree within depth_span_ratio. Measured: CesiumMan in human_woman, her
  // clip's bone-length error 0.00442 → 0.00413 (hand-placed joints 0.00434); dropping the fitted
  // bones from the 60° test: CesiumMan → RobotExpressive 3.24 → 3.03 % of the height.
  if (opt.depth_span_ratio > 1 && r.skeleton_prior_used == 0) {
    const int front = opt.source_front % 3;
    const Eigen::Vector3d as = jf_axis(front), at = R.transpose() * as;
    Eigen::MatrixXd P = out.P;
    for (int k = 0; k < out.size(); ++k) {
      if (kept_in_place(k)) continue;
      const Eigen::Vector3d ps = source_joints.P.row(src_of[k]).transpose();
      // The source joint's spans along its three axes: front must not be the longest. bs, fs_: its
      // distances to the surface behind and ahead.
      int longest = -1;
      double longest_span = -1, bs = -1, fs_ = -1;
      for (int a = 0; a < 3; ++a) {
        const double b = in.bvh_s.ray_first_hit(ps, -jf_axis(a)), f = in.bvh_s.ray_first_hit(ps, jf_axis(a));
        const double span = b > 0 && f > 0 ? b + f : std::numeric_limits<double>::infinity();
        if (span > longest_span) longest_span = span, longest = a;
        if (a == front) bs = b, fs_ = f;
      }
      if (longest == front) continue;
      bool along_bone = false;
      for (int c = -1; c < out.size() && !along_bone; ++c) {
        const int o = c < 0 ? out.parent[k] : (out.parent[c] == k ? c : -1);
        if (o < 0) continue;
        const Eigen::Vector3d ds = (source_joints.P.row(src_of[o]) - source_joints.P.row(src_of[k])).transpose().normalized();
        along_bone = !(std::abs(ds[front]) <= 0.5);
      }
      if (along_bone) continue;
      const Eigen::Vector3d p = out.P.row(k).transpose();
      const double bt = bvh_t.ray_first_hit(p, -at), ft_ = bvh_t.ray_first_hit(p, at);
      if (!(bs > 0 && fs_ > 0 && bt > 0 && ft_ > 0)) continue;
      if (in.bvh_s.inside(ps + (fs_ + es) * as) || in.bvh_s.inside(ps - (bs + es) * as) || bvh_t.inside(p + (ft_ + et) * at) ||
          bvh_t.inside(p - (bt + et) * at))
        continue;
      if (!spans_agree(bs, fs_, bt, ft_, opt.depth_span_ratio)) continue;
      const Eigen::Vector3d q = p + (-bt + bs / (bs + fs_) * (bt + ft_)) * at;
      if (q.allFinite() && inside_t(q)) P.row(k) = q.transpose(), ++r.depth_moved;
    }
    out.P = P;
  }
  // Middle joints where limbs branch off to both sides (hips, chest: where the voxel skeletons
  // branch): a source joint within 0.01 of the source's height of its middle plane, with placed
  // children on both sides of it, moves sideways to the middle of the target's section plus the
  // source joint's own offset from the middle of its section, scaled by the heights:
  //   p ← p + (½ (f_t − b_t) + ½ (b_s − f_s) · H_t / H_s) · side_t.
  // The rays leave the union of the parts (the robot's hip balls lie inside its pelvis; one closed
  // mesh: the first hit). The widths agree within middle_span_ratio, looser than depths: bodies
  // differ in breadth (the robot's pelvis is 2.0× CesiumMan's, scaled). Measured: CesiumMan →
  // RobotExpressive 3.03 → 2.81 % of the height (his root 4.4 → 2.2 %), Knight → robot 4.20 →
  // 4.17 %, human_woman and wolf0 within 0.01 points. Tried and dropped: the source's fraction of
  // the width instead of its offset (a width through her arms scaled CesiumMan's 0.005 off-middle
  // to 0.012 in human_woman: her clip's bone-length error 0.00413 → 0.00433); every middle joint
  // (wolf0's tail joints centred onto each other: its bone-length error 0.01043 → 0.01102).
  if (opt.middle_span_ratio > 1 && r.skeleton_prior_used == 0) {
    const Eigen::Vector3d& as = side;  // unit: two distinct coordinate axes
    const Eigen::Vector3d at = R.transpose() * as;
    auto on_middle = [&](int k) { return std::abs(as.dot(source_joints.P.row(src_of[k]).transpose() - mid_s)) <= 0.01 * fs.H; };
    // The first of the ray's (up to 32) crossings past which it is outside every part, or −1.
    auto exit_distance = [](const TriangleBvh& bvh, const Eigen::Vector3d& p, const Eigen::Vector3d& dir, double eps) {
      for (double t : bvh.ray_crossings(p, dir, std::numeric_limits<double>::infinity(), 32, eps))
        if (!bvh.inside(p + (t + eps) * dir)) return t;
      return -1.0;
    };
    for (int k = 0; k < out.size(); ++k) {
      if (kept_in_place(k) || !on_middle(k)) continue;
      const Eigen::Vector3d ps = source_joints.P.row(src_of[k]).transpose(), p = out.P.row(k).transpose();
      bool left = false, right = false;
      for (int c = 0; c < out.size(); ++c)
        if (out.parent[c] == k) {
          const double x = as.dot(source_joints.P.row(src_of[c]).transpose() - mid_s);
          left = left || x < -0.01 * fs.H, right = right || x > 0.01 * fs.H;
        }
      if (!left || !right) continue;
      const double bs = exit_distance(in.bvh_s, ps, -as, es), fs_ = exit_distance(in.bvh_s, ps, as, es);
      const double bt = exit_distance(bvh_t, p, -at, et), ft_ = exit_distance(bvh_t, p, at, et);
      if (!(bs > 0 && fs_ > 0 && bt > 0 && ft_ > 0)) continue;
      if (!spans_agree(bs, fs_, bt, ft_, opt.middle_span_ratio)) continue;
      const Eigen::Vector3d q = p + (0.5 * (ft_ - bt) + 0.5 * (bs - fs_) * ft.H / fs.H) * at;
      if (q.allFinite() && inside_t(q)) out.P.row(k) = q.transpose(), ++r.middle_moved;
    }
  }

  // 5f. Mirror pairs. A target that is its own mirror image (human_woman: within 0.2 % of her height)
  // gets joint pairs that are mirror images too, up to the source's own asymmetry: the voxel
  // skeletons are not exactly symmetric, and her fitted knees came out 2.7 % of her height apart in
  // height, her ankles 4.3 %. Each joint whose mirror image in the source is another joint (within
  // 0.03 of the source's height, each the other's nearest) is set to
  //   ½ (p_k + M_t p_l) + ½ S (s_k − M_s s_l),
  // p the fitted joints, s the source's, M the mirror across each middle plane (normal to up × front,
  // through the bounding box's centre), S the global similarity's linear part (R, H_t/H_s): the mean
  // of the joint and its partner's mirror image, plus half the source's own difference between them,
  // so a fit that was exact stays exact (self fits). Joints on the middle plane are left alone
  // (moved onto it, the wolf's tail joints moved up to 1.3 % of its height and its clip's bone-length
  // error rose 6 %). Only when both surfaces are mirror images of themselves within mirror_symmetry
  // × height (mean distance of the mirrored vertices): RobotExpressive's arms hang at different
  // heights (1.24 %), and a source posed asymmetrically would carry its pose as its own asymmetry.
  if (opt.mirror_symmetry > 0 && out.size() > 1) {
    const Eigen::Vector3d& side_s = side;
    const Eigen::Vector3d side_t = R.transpose() * side;
    const Eigen::Vector3d &cs = mid_s, &ct = mid_t;
    const auto mirror = [](const Eigen::Vector3d& p, const Eigen::Vector3d& c, const Eigen::Vector3d& n) -> Eigen::Vector3d {
      return p - 2 * (p - c).dot(n) * n;
    };
    // Mean distance of the mirrored surface from itself (every k-th vertex, ~1000), × height.
    const auto asymmetry = [&](const Eigen::MatrixXd& V, const TriangleBvh& bvh, const Eigen::Vector3d& c,
                               const Eigen::Vector3d& n, double height) {
      double sum = 0;
      int samples = 0;
      const int stride = std::max(1, int(V.rows() / 1000));
      for (int i = 0; i < V.rows(); i += stride, ++samples) sum += std::sqrt(bvh.closest_point(mirror(V.row(i).transpose(), c, n)).sq_distance);
      return sum / std::max(1, samples) / height;
    };
    const int n = out.size();
    std::vector<int> partner(n, -1);
    bool pairs = false;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d m = mirror(source_joints.P.row(src_of[k]).transpose(), cs, side_s);
      double best = 0.03 * fs.H;
      for (int l = 0; l < n; ++l)
        if (const double d = (source_joints.P.row(src_of[l]).transpose() - m).norm(); d < best) best = d, partner[k] = l;
    }
    for (int k = 0; k < n; ++k) pairs = pairs || (partner[k] >= 0 && partner[k] != k && partner[partner[k]] == k);
    if (pairs && asymmetry(Vt, bvh_t, ct, side_t, ft.H) <= opt.mirror_symmetry &&
        asymmetry(Vs, in.bvh_s, cs, side_s, fs.H) <= opt.mirror_symmetry) {
      const double scale = ft.H / fs.H;
      Eigen::MatrixXd P = out.P;
      for (int k = 0; k < n; ++k) {
        const int l = partner[k];
        if (l < 0 || l == k || partner[l] != k) continue;
        if (std::find(outside.begin(), outside.end(), out.names[k]) != outside.end() ||
            std::find(outside.begin(), outside.end(), out.names[l]) != outside.end())
          continue;
        const Eigen::Vector3d own = source_joints.P.row(src_of[k]).transpose() -
                                    mirror(source_joints.P.row(src_of[l]).transpose(), cs, side_s);
        const Eigen::Vector3d q = 0.5 * (out.P.row(k).transpose() + mirror(out.P.row(l).transpose(), ct, side_t)) +
                                  0.5 * scale * (R.transpose() * own);
        if (q.allFinite() && inside_t(q)) P.row(k) = q.transpose(), ++r.mirrored;
      }
      out.P = P;
    }
  }

  // Limbs that cross the body's middle: a bone whose two joints lie well to one side in the source
  // (beyond 0.05 of its height from its middle plane, the same side) but on opposite sides in the
  // target (beyond 0.01). A fit whose skeleton is broken (human_woman at 48 cells, centred grid:
  // each leg ran from one hip to the other foot; mean error 21 %, bones' disagreement only 0.40)
  // says so; the whole fit turned round is not caught here.
  {
    auto side_s = [&](int k) {
      const double x = side.dot(source_joints.P.row(src_of[k]).transpose() - mid_s) / fs.H;
      return x > 0.05 ? 1 : x < -0.05 ? -1 : 0;
    };
    auto side_t = [&](int k) {
      const double x = side.dot(R * (out.P.row(k).transpose() - mid_t)) / ft.H;
      return x > 0.01 ? 1 : x < -0.01 ? -1 : 0;
    };
    std::vector<std::string> crossing;
    for (int k = 0; k < out.size(); ++k) {
      const int q = out.parent[k];
      if (q < 0 || src_of[k] < 0 || src_of[q] < 0) continue;
      const int a = side_s(k), b = side_s(q), ta = side_t(k), tb = side_t(q);
      if (a != 0 && a == b && ta != 0 && tb != 0 && ta != tb) crossing.push_back(out.names[q] + " → " + out.names[k]);
    }
    if (!crossing.empty())
      r.warnings.push_back("the fitted limbs cross the body's middle (" + jf_join(crossing, 4) +
                           "): the skeleton is likely broken here; check the joints, pin a few with markers, or try another "
                           "skeleton resolution");
  }

  // Markers: pin, and drag chain neighbours within marker_reach bones.
  if (!markers.empty()) {
    std::vector<uint8_t> pinned(out.size(), 0);
    std::vector<Eigen::Vector3d> delta(out.size(), Eigen::Vector3d::Zero());
    for (const JointMarker& m : markers) {
      const int k = out.find(m.name);
      if (k < 0) {
        const bool exists = source_joints.find(m.name) >= 0;
        return fail(StatusCode::InvalidArgument,
                    "marker '" + m.name + "' " +
                        (exists ? std::string("names a source joint outside the source surface, which is not placed")
                                : "names no source joint; source joints: " + jf_join(source_joints.names, 60)));
      }
      if (!m.position.allFinite() || !inside_t(m.position))
        return fail(StatusCode::InvalidArgument, "marker '" + m.name + "' lies outside the target surface; click on or inside the mesh");
      pinned[k] = 1;
      delta[k] = m.position - out.P.row(k).transpose();
    }
    // Hops between joints along the hierarchy (small sets: BFS per pinned joint).
    const std::vector<std::vector<int>> adj = jf_bone_adjacency(out.parent);
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(out.size(), 3);
    Eigen::VectorXd W = Eigen::VectorXd::Zero(out.size());
    for (int k = 0; k < out.size(); ++k) {
      if (!pinned[k]) continue;
      const std::vector<int> hop = jf_hops(adj, {k}, opt.marker_reach, pinned);
      for (int i = 0; i < out.size(); ++i) {
        if (i == k || hop[i] < 0) continue;
        const double w = 1.0 - double(hop[i]) / (opt.marker_reach + 1);
        D.row(i) += w * delta[k].transpose();
        W[i] += w;
      }
    }
    for (int i = 0; i < out.size(); ++i) {
      if (pinned[i]) {
        out.P.row(i) += delta[i].transpose();
        continue;
      }
      if (W[i] <= 0) continue;
      const Eigen::Vector3d p = out.P.row(i).transpose() + D.row(i).transpose() / std::max(1.0, W[i]);
      if (inside_t(p)) out.P.row(i) = p.transpose();
    }
    outside.erase(std::remove_if(outside.begin(), outside.end(), [&](const std::string& n) {
                    const int k = out.find(n);
                    return k >= 0 && inside_t(out.P.row(k).transpose());
                  }),
                  outside.end());
  }
  if (!outside.empty())
    return fail(StatusCode::InvalidArgument, "joint" + std::string(outside.size() > 1 ? "s " : " ") + jf_join(outside) +
                                                 " could not be placed inside the target; pin them with markers");
  if (!out.P.allFinite()) return fail(StatusCode::NumericalError, "fitted joints are not finite");
  if (!r.skipped.empty())
    r.warnings.push_back(std::to_string(r.skipped.size()) + " source joints lie outside the source surface and are not placed: " +
                         jf_join(r.skipped));
  progress.update("fitting", 1.0);
  return r;
}

}  // namespace joint_fitting_detail

JointFitResult fit_joints(const Eigen::MatrixXd& Vs, const Eigen::MatrixXi& Fs, const JointSet& source_joints,
                          const Eigen::MatrixXd& Vt, const Eigen::MatrixXi& Ft, const std::vector<JointMarker>& markers,
                          const JointFitOptions& opt, const Progress& progress) {
  using namespace joint_fitting_detail;
  JointFitResult r;
  auto fail = [&](StatusCode c, const std::string& m) {
    r.status = Status::error(c, m);
    return r;
  };
  if (opt.source_up < 0 || opt.source_up > 5 || opt.target_up < -1 || opt.target_up > 5 || opt.source_front < 0 ||
      opt.source_front > 5 || opt.target_front < -1 || opt.target_front > 5 || opt.source_up % 3 == opt.source_front % 3 ||
      (opt.target_up >= 0 && opt.target_front >= 0 && opt.target_up % 3 == opt.target_front % 3))
    return fail(StatusCode::InvalidArgument, "up axes must be -1 (target: detect) or 0..5 (+x, +y, +z, -x, -y, -z)");
  if (source_joints.size() < 2) return fail(StatusCode::InvalidArgument, "the source has fewer than 2 joints");
  // The two curve skeletons and surface trees are independent: with a second thread, the source's
  // are built on a pool task while this thread builds the target's (same results either way; only
  // this thread reports progress, and the task stops when this thread returns early).
  TriangleBvh bvh_s, bvh_t;
  {
    CurveSkeleton source_skeleton;  // the task's (r is copied by an early return while it may run)
    StoppableTask source_task;  // declared after what it writes: an early return stops and waits for it
    const bool overlap = MM_HAS_THREADS && max_threads() > 1;
    if (overlap) {
      source_task = StoppableTask([&source_skeleton, &bvh_s, &Vs, &Fs, &opt](const Progress& watch) {
        source_skeleton = curve_skeleton(Vs, Fs, opt.skeleton, watch);
        if (source_skeleton.status.ok()) bvh_s.build(Vs, Fs);
      });
    } else {
      r.source_skeleton = curve_skeleton(Vs, Fs, opt.skeleton, progress.sub(0, 0.45));
      if (!r.source_skeleton.status.ok())
        return fail(r.source_skeleton.status.code, "source skeleton: " + r.source_skeleton.status.message);
      bvh_s.build(Vs, Fs);
    }
    r.target_skeleton = curve_skeleton(Vt, Ft, opt.skeleton, progress.sub(overlap ? 0.0 : 0.45, 0.9));
    if (!r.target_skeleton.status.ok())
      return fail(r.target_skeleton.status.code, "target skeleton: " + r.target_skeleton.status.message);
    bvh_t.build(Vt, Ft);
    if (source_task.valid()) {
      source_task.wait();
      r.source_skeleton = std::move(source_skeleton);
      if (!r.source_skeleton.status.ok())
        return fail(r.source_skeleton.status.code, "source skeleton: " + r.source_skeleton.status.message);
    }
  }

  // Source joints inside the source surface.
  const double tol_s = opt.inside_tolerance * (Vs.colwise().maxCoeff() - Vs.colwise().minCoeff()).norm();
  const double tol_t = opt.inside_tolerance * (Vt.colwise().maxCoeff() - Vt.colwise().minCoeff()).norm();
  auto inside_s = [&](const Eigen::Vector3d& p) { return bvh_s.closest_point(p).sq_distance <= tol_s * tol_s || bvh_s.inside(p); };
  std::vector<int> used;
  for (int j = 0; j < source_joints.size(); ++j) {
    if (inside_s(source_joints.P.row(j).transpose())) used.push_back(j);
    else r.skipped.push_back(source_joints.names[j]);
  }
  if (used.size() < 2) return fail(StatusCode::InvalidArgument, "fewer than 2 source joints lie inside the source surface");
  // Step 5d's ball parts of both characters (sizes against the longest side of each).
  const auto balls_of = [&](const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
    return opt.ball_joint_reach > 0 ? ball_parts(V, F, (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff(), opt.balls)
                                    : std::vector<BallPart>{};
  };
  const std::vector<BallPart> balls_s = balls_of(Vs, Fs), balls_t = balls_of(Vt, Ft);
  const JfInputs in{Vs, Vt, Fs, Ft, source_joints, used, bvh_s, bvh_t, tol_t, markers, opt, progress, balls_s, balls_t};
  // The source's curve skeleton first (Voxel, Auto); Auto falls back to the source's own bones
  // when a source limb finds no partner (blocky, many-part sources: KayKit's 24 limb ends).
  // Markers on a lost limb lift its refusal (their joints place it) only where no tree fits
  // without that: Auto first tries the source's own bones, which place such a limb from the rig
  // (KayKit Knight → human_woman with a marker on her hips: 9.4 % of the height on the curve
  // skeleton with the limb lifted, 4.9 % on the bones; 5.8 % without markers).
  JointFitResult voxel;
  const bool auto_tree = opt.source_skeleton == SourceSkeleton::Auto;
  if (opt.source_skeleton != SourceSkeleton::Bones) {
    bool lost = false;
    voxel = jf_fit_on_skeletons(r, in, true, &lost, !auto_tree);
    voxel.source_tree = SourceSkeleton::Voxel;
    if (voxel.status.ok() || !auto_tree || !lost) return voxel;
  }
  const size_t voxel_ends = r.source_skeleton.leaves().size();
  // The curve skeleton's inputs, for the markers' last try below (only then worth the copy).
  std::optional<JointFitResult> curve_r;
  if (!markers.empty() && auto_tree) curve_r = r;
  r.source_skeleton = jf_bone_skeleton(r.source_skeleton, source_joints, used, bvh_s);
  if (!r.source_skeleton.status.ok()) return fail(r.source_skeleton.status.code, r.source_skeleton.status.message);
  // Auto: the bones without lifting lost limbs, then the markers lift the curve skeleton's, then
  // the bones' (the Fox in a tailless horse with a pin on the tail: the bones had lost a foot too,
  // lifted by that pin 5 bones away, and put a hind leg's joints across the body).
  JointFitResult bones = jf_fit_on_skeletons(r, in, false, nullptr, !curve_r);
  bones.source_tree = SourceSkeleton::Bones;
  if (opt.source_skeleton == SourceSkeleton::Bones) return bones;
  if (!bones.status.ok()) {
    if (curve_r) {  // neither tree fits: the curve skeleton's lost limbs from the markers, then the bones'
      JointFitResult lifted = jf_fit_on_skeletons(*curve_r, in, true, nullptr, true);
      lifted.source_tree = SourceSkeleton::Voxel;
      if (lifted.status.ok()) return lifted;
      JointFitResult bones_lifted = jf_fit_on_skeletons(r, in, false, nullptr, true);
      bones_lifted.source_tree = SourceSkeleton::Bones;
      if (bones_lifted.status.ok()) bones = std::move(bones_lifted);
    }
  }
  if (!bones.status.ok()) {
    voxel.status = Status::error(voxel.status.code, voxel.status.message + " (the source's own bones do not fit either: " +
                                                        bones.status.message + ")");
    return voxel;
  }
  bones.warnings.insert(bones.warnings.begin(),
                        "the source's curve skeleton (" + std::to_string(voxel_ends) +
                            " limb ends) has limbs the target lacks; fitted the source's own bones instead");
  return bones;
}

}  // namespace mm
