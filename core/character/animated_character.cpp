#include "character/animated_character.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace mm {

namespace character_detail {

Eigen::Matrix4d trs_matrix(const Eigen::Vector3d& t, const Eigen::Quaterniond& r, const Eigen::Vector3d& s) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M.topLeftCorner<3, 3>() = r.normalized().toRotationMatrix() * s.asDiagonal();
  M.topRightCorner<3, 1>() = t;
  return M;
}

// Index k with times[k] ≤ t < times[k+1] (t already clamped into [front, back]).
int key_interval(const Eigen::VectorXd& times, double t) {
  const int n = static_cast<int>(times.size());
  const double* b = times.data();
  int k = static_cast<int>(std::upper_bound(b, b + n, t) - b) - 1;
  return std::clamp(k, 0, std::max(0, n - 2));
}

Eigen::Quaterniond quat(const Eigen::VectorXd& v) { return Eigen::Quaterniond(v[3], v[0], v[1], v[2]); }

// Channel value at time t: 3-vector (T, S) or quaternion coefficients x y z w (R).
Eigen::VectorXd sample_channel(const AnimationChannel& ch, double t) {
  using I = AnimationChannel::Interpolation;
  const int n = static_cast<int>(ch.times.size());
  const bool cubic = ch.interpolation == I::CubicSpline;
  auto value = [&](int k) -> Eigen::VectorXd {
    return cubic ? Eigen::VectorXd(ch.values.row(3 * k + 1).transpose()) : Eigen::VectorXd(ch.values.row(k).transpose());
  };
  if (n == 1 || t <= ch.times[0]) return value(0);
  if (t >= ch.times[n - 1]) return value(n - 1);
  const int k = key_interval(ch.times, t);
  const double t0 = ch.times[k], t1 = ch.times[k + 1], dt = t1 - t0;
  const double u = dt > 0 ? (t - t0) / dt : 0.0;
  const bool rotation = ch.path == AnimationChannel::Path::Rotation;
  if (ch.interpolation == I::Step) return value(k);
  if (ch.interpolation == I::Linear) {
    if (rotation) {
      Eigen::Quaterniond q0 = quat(value(k)), q1 = quat(value(k + 1));
      const Eigen::Quaterniond q = q0.normalized().slerp(u, q1.normalized());  // Eigen takes the short arc
      return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
    }
    return (1 - u) * value(k) + u * value(k + 1);
  }
  // CUBICSPLINE (glTF spec, Appendix C): p(u) = (2u³−3u²+1)v0 + (u³−2u²+u)·dt·b0 + (−2u³+3u²)v1 + (u³−u²)·dt·a1.
  const Eigen::VectorXd v0 = ch.values.row(3 * k + 1).transpose(), b0 = ch.values.row(3 * k + 2).transpose();
  const Eigen::VectorXd v1 = ch.values.row(3 * (k + 1) + 1).transpose(), a1 = ch.values.row(3 * (k + 1)).transpose();
  const double u2 = u * u, u3 = u2 * u;
  Eigen::VectorXd p = (2 * u3 - 3 * u2 + 1) * v0 + (u3 - 2 * u2 + u) * dt * b0 + (-2 * u3 + 3 * u2) * v1 + (u3 - u2) * dt * a1;
  if (rotation) p.normalize();
  return p;
}

}  // namespace character_detail

Matrix4dList node_world_matrices(const AnimatedCharacter& c, int clip, double t) {
  using namespace character_detail;
  const int nn = static_cast<int>(c.node_names.size());
  std::vector<Eigen::Vector3d> T = c.node_t, S = c.node_s;
  std::vector<Eigen::Quaterniond, Eigen::aligned_allocator<Eigen::Quaterniond>> R = c.node_r;
  if (clip >= 0 && clip < static_cast<int>(c.clips.size()))
    for (const AnimationChannel& ch : c.clips[clip].channels) {
      if (c.node_has_matrix[ch.node]) continue;  // the spec forbids animating matrix nodes
      const Eigen::VectorXd v = sample_channel(ch, t);
      switch (ch.path) {
        case AnimationChannel::Path::Translation: T[ch.node] = v.head<3>(); break;
        case AnimationChannel::Path::Scale: S[ch.node] = v.head<3>(); break;
        case AnimationChannel::Path::Rotation: R[ch.node] = quat(v); break;
        default: break;
      }
    }
  Matrix4dList world(nn, Eigen::Matrix4d::Identity());
  std::vector<bool> done(nn, false);
  // Parents come before children in the traversal; nodes outside the scene are resolved lazily.
  std::vector<int> order = c.traversal;
  for (int i = 0; i < nn; ++i)
    if (std::find(c.traversal.begin(), c.traversal.end(), i) == c.traversal.end()) order.push_back(i);
  for (int i : order) {
    const Eigen::Matrix4d local = c.node_has_matrix[i] ? c.node_matrix[i] : trs_matrix(T[i], R[i], S[i]);
    const int p = c.node_parent[i];
    world[i] = (p >= 0 && done[p]) ? Eigen::Matrix4d(world[p] * local) : local;
    done[i] = true;
  }
  return world;
}

Eigen::MatrixXd posed_vertices(const AnimatedCharacter& c, const Matrix4dList& world) {
  Eigen::MatrixXd V(c.V_rest.rows() > 0 ? c.V_rest.rows() : 0, 3);
  int total = 0;
  for (const CharacterPart& p : c.parts) total = std::max(total, p.first_vertex + p.num_vertices);
  V.resize(total, 3);
  for (const CharacterPart& p : c.parts) {
    if (p.skin < 0) {
      const Eigen::Matrix4d& M = world[p.node];
      for (int v = 0; v < p.num_vertices; ++v)
        V.row(p.first_vertex + v) = (M.topLeftCorner<3, 3>() * p.local.row(v).transpose() + M.topRightCorner<3, 1>()).transpose();
      continue;
    }
    const CharacterSkin& sk = c.skins[p.skin];
    Matrix4dList J(sk.joints.size());
    for (size_t j = 0; j < sk.joints.size(); ++j) J[j] = world[sk.joints[j]] * sk.inverse_bind[j];
    for (int v = 0; v < p.num_vertices; ++v) {
      Eigen::Matrix<double, 3, 4> B = Eigen::Matrix<double, 3, 4>::Zero();
      for (int k = 0; k < p.weights.cols(); ++k)
        if (p.weights(v, k) != 0) B += p.weights(v, k) * J[p.joints(v, k)].topRows<3>();
      V.row(p.first_vertex + v) = (B.leftCols<3>() * p.local.row(v).transpose() + B.col(3)).transpose();
    }
  }
  return V;
}

Eigen::MatrixXd pose_at(const AnimatedCharacter& c, int clip, double t) {
  return posed_vertices(c, node_world_matrices(c, clip, t));
}

Status find_clip(const AnimatedCharacter& c, const std::string& name, int* index) {
  *index = -1;
  if (c.clips.empty()) return Status::error(StatusCode::InvalidArgument, "the source has no animation clips");
  if (name.empty()) {
    *index = 0;
    return Status::success();
  }
  std::string names;
  for (size_t i = 0; i < c.clips.size(); ++i) {
    if (c.clips[i].name == name) {
      *index = static_cast<int>(i);
      return Status::success();
    }
    if (i < 20) names += (i ? ", " : "") + c.clips[i].name;
  }
  if (c.clips.size() > 20) names += ", ... (" + std::to_string(c.clips.size()) + " clips)";
  return Status::error(StatusCode::InvalidArgument, "clip '" + name + "' not found; the source has: " + names);
}

JointSet character_joints(const AnimatedCharacter& c) {
  JointSet J;
  if (c.main_skin < 0) return J;
  const CharacterSkin& sk = c.skins[c.main_skin];
  const Matrix4dList world = node_world_matrices(c, -1, 0);
  const int n = static_cast<int>(sk.joints.size());
  J.P.resize(n, 3);
  std::map<int, int> slot_of;
  for (int j = 0; j < n; ++j) slot_of[sk.joints[j]] = j;
  for (int j = 0; j < n; ++j) {
    J.names.push_back(c.node_names[sk.joints[j]]);
    J.P.row(j) = world[sk.joints[j]].topRightCorner<3, 1>().transpose();
    int p = c.node_parent[sk.joints[j]];
    while (p >= 0 && !slot_of.count(p)) p = c.node_parent[p];
    J.parent.push_back(p >= 0 ? slot_of[p] : -1);
  }
  return J;
}

SkinWeights character_skin_weights(const AnimatedCharacter& c) {
  int K = 1;
  for (const CharacterPart& p : c.parts) K = std::max<int>(K, static_cast<int>(p.weights.cols()));
  SkinWeights W;
  W.index = Eigen::MatrixXi::Zero(c.V_rest.rows(), K);
  W.weight = Eigen::MatrixXd::Zero(c.V_rest.rows(), K);
  for (const CharacterPart& p : c.parts)
    for (int v = 0; v < p.num_vertices; ++v) {
      const int row = p.first_vertex + v;
      if (p.skin < 0) {
        W.index(row, 0) = p.node;
        W.weight(row, 0) = 1;
        continue;
      }
      for (int k = 0; k < p.weights.cols(); ++k) {
        W.index(row, k) = c.skins[p.skin].joints[p.joints(v, k)];
        W.weight(row, k) = p.weights(v, k);
      }
    }
  return W;
}

SkinWeights joint_skin_weights(const AnimatedCharacter& c, const JointSet& J) {
  SkinWeights W = character_skin_weights(c);
  std::map<std::string, int> row_of;
  for (int j = 0; j < J.size(); ++j) row_of[J.names[j]] = j;
  const int n = static_cast<int>(c.node_names.size());
  std::vector<int> joint_of(n, -1);
  for (int i = 0; i < n; ++i) {
    int a = i;
    for (int guard = 0; a >= 0 && guard <= n; ++guard) {
      const auto it = row_of.find(c.node_names[a]);
      if (it != row_of.end()) {
        joint_of[i] = it->second;
        break;
      }
      a = c.node_parent[a];
    }
  }
  for (Eigen::Index v = 0; v < W.index.rows(); ++v)
    for (Eigen::Index k = 0; k < W.index.cols(); ++k) {
      const int node = W.index(v, k);
      W.index(v, k) = node >= 0 && node < n ? joint_of[node] : -1;
    }
  return W;
}

Matrix4dList node_motions(const AnimatedCharacter& c, const Matrix4dList& world) {
  const Matrix4dList rest = node_world_matrices(c, -1, 0);
  Matrix4dList M(world.size());
  for (size_t i = 0; i < world.size(); ++i) M[i] = world[i] * rest[i].inverse();
  return M;
}

std::vector<double> frame_times(const AnimationClip& clip, double fps, double start, double end) {
  if (start < 0 && end < 0) {
    start = clip.start;
    end = clip.end;
  }
  std::vector<double> t;
  if (!(fps > 0) || !(end >= start)) return t;
  const int n = static_cast<int>(std::floor((end - start) * fps + 1e-9)) + 1;
  for (int k = 0; k < n; ++k) t.push_back(start + k / fps);
  if (end - t.back() > 1e-6) t.push_back(end);
  return t;
}

}  // namespace mm
