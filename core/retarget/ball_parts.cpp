#include "retarget/ball_parts.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mesh/topology.h"
#include "mesh/weld.h"

namespace mm {

std::vector<BallPart> ball_parts(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, double height,
                                 const BallPartOptions& opt) {
  std::vector<BallPart> out;
  if (V.rows() == 0 || F.rows() == 0 || !(height > 0) || F.cols() != 3) return out;
  WeldOptions wo;
  wo.tolerance = opt.weld_tolerance;
  const WeldResult w = weld_vertices(V, F, wo);
  int count = 0;
  const Eigen::VectorXi comp = vertex_components(w.F, int(w.V.rows()), &count);
  if (count < 2) return out;
  // A part is closed when each of its edges has exactly two faces (edge_uses: once for the mesh).
  std::vector<char> open(count, 0);
  for (const EdgeUse& e : edge_uses(w.F))
    if (e.faces != 2) open[comp[e.i]] = 1;
  const VertexBuckets faces = bucket_by_vertex(count, int(w.F.rows()), [&](int f) { return comp[w.F(f, 0)]; });
  const double pi = 3.14159265358979323846;
  for (int c = 0; c < count; ++c) {
    if (open[c]) continue;
    const int begin = faces.start[c], end = faces.start[c + 1];
    if (end - begin < 4) continue;  // a closed surface has at least 4 triangles
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    double area = 0, volume = 0;
    for (int i = begin; i < end; ++i) {
      const int f = faces.items[i];
      const Eigen::Vector3d a = w.V.row(w.F(f, 0)).transpose(), b = w.V.row(w.F(f, 1)).transpose(),
                            c3 = w.V.row(w.F(f, 2)).transpose();
      lo = lo.cwiseMin(a).cwiseMin(b).cwiseMin(c3);
      hi = hi.cwiseMax(a).cwiseMax(b).cwiseMax(c3);
      area += 0.5 * (b - a).cross(c3 - a).norm();
      // Signed volume of the tetrahedron (0, a, b, c) and its centroid's moment (closed surface:
      // the sums are the enclosed volume and its first moment whatever the origin).
      const double v = a.dot(b.cross(c3)) / 6.0;
      volume += v;
      moment += v * (a + b + c3) / 4.0;
    }
    if ((hi - lo).maxCoeff() > opt.max_size * height) continue;
    if (!(area > 0) || !(std::abs(volume) > 0)) continue;
    const double vol = std::abs(volume);
    BallPart ball;
    ball.roundness = std::cbrt(pi) * std::pow(6.0 * vol, 2.0 / 3.0) / area;
    if (!(ball.roundness >= opt.min_roundness)) continue;
    ball.centre = moment / volume;
    ball.radius = std::cbrt(3.0 * vol / (4.0 * pi));
    if (!ball.centre.allFinite()) continue;
    out.push_back(ball);
  }
  return out;
}

std::vector<int> pair_balls_with_joints(const std::vector<BallPart>& balls, const Eigen::MatrixXd& P,
                                        const std::vector<int>& parent, double reach) {
  std::vector<int> out(balls.size(), -1);
  if (balls.empty() || P.rows() == 0) return out;
  const bool bones = static_cast<Eigen::Index>(parent.size()) == P.rows();
  std::vector<std::vector<int>> neighbours(P.rows());
  if (bones)
    for (int i = 0; i < P.rows(); ++i)
      if (parent[i] >= 0 && parent[i] < P.rows()) neighbours[i].push_back(parent[i]), neighbours[parent[i]].push_back(i);
  for (size_t b = 0; b < balls.size(); ++b) {
    const Eigen::Vector3d c = balls[b].centre;
    int i = -1;
    double d = std::numeric_limits<double>::infinity();
    for (int k = 0; k < P.rows(); ++k) {
      if (!P.row(k).allFinite()) continue;
      const double e = (P.row(k).transpose() - c).norm();
      if (e < d) d = e, i = k;
    }
    if (i < 0 || d > reach * balls[b].radius) continue;
    const Eigen::Vector3d p = P.row(i).transpose();
    bool nearest = true;
    for (size_t o = 0; o < balls.size() && nearest; ++o) nearest = (balls[o].centre - p).norm() >= d || o == b;
    for (int n : neighbours[i]) {
      if (!nearest || !P.row(n).allFinite()) continue;
      const Eigen::Vector3d bone = P.row(n).transpose() - p;
      const double len2 = bone.squaredNorm();
      nearest = !(len2 > 0) || (c - p).dot(bone) < 0.4 * len2;
    }
    if (nearest) out[b] = i;
  }
  return out;
}

}  // namespace mm
