#include "io/gltf_animation.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "io/gltf_accessor.h"
#include "io/gltf_document.h"

namespace mm::io {

namespace gltf_anim_detail {

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

}  // namespace gltf_anim_detail

CharacterResult animated_character(const Asset& asset, const CharacterOptions& opt) {
  using namespace gltf_anim_detail;
  CharacterResult r;
  const tinygltf::Model* mp = gltf_model(asset);
  if (!mp) {
    r.status = Status::error(StatusCode::Unsupported,
                             "'" + asset.source_name + "' is not a glTF file: skins and animations need .glb or .gltf");
    return r;
  }
  const tinygltf::Model& m = *mp;
  AnimatedCharacter& c = r.character;
  const int nn = static_cast<int>(m.nodes.size());
  c.node_names.resize(nn);
  c.node_parent.assign(nn, -1);
  c.node_has_matrix.assign(nn, false);
  c.node_mesh.assign(nn, -1);
  c.node_matrix.assign(nn, Eigen::Matrix4d::Identity());
  c.node_t.assign(nn, Eigen::Vector3d::Zero());
  c.node_s.assign(nn, Eigen::Vector3d::Ones());
  c.node_r.assign(nn, Eigen::Quaterniond::Identity());
  std::map<std::string, int> seen;
  for (int i = 0; i < nn; ++i) {
    const tinygltf::Node& n = m.nodes[i];
    std::string name = n.name.empty() ? "node" : n.name;
    if (seen.count(name) || n.name.empty()) name += "#" + std::to_string(i);
    seen[name] = i;
    c.node_names[i] = name;
    c.node_mesh[i] = n.mesh >= 0 && n.mesh < static_cast<int>(m.meshes.size()) ? n.mesh : -1;
    for (int ch : n.children)
      if (ch >= 0 && ch < nn) c.node_parent[ch] = i;
    if (n.matrix.size() == 16) {
      c.node_has_matrix[i] = true;
      for (int k = 0; k < 16; ++k) c.node_matrix[i](k % 4, k / 4) = n.matrix[k];  // column-major
    } else {
      if (n.translation.size() == 3) c.node_t[i] = Eigen::Vector3d(n.translation[0], n.translation[1], n.translation[2]);
      if (n.scale.size() == 3) c.node_s[i] = Eigen::Vector3d(n.scale[0], n.scale[1], n.scale[2]);
      if (n.rotation.size() == 4) c.node_r[i] = Eigen::Quaterniond(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
    }
  }
  // Scene traversal (default scene or 0; all root nodes when there is no scene).
  std::vector<int> roots;
  const int scene = m.defaultScene >= 0 && m.defaultScene < static_cast<int>(m.scenes.size()) ? m.defaultScene : 0;
  if (!m.scenes.empty()) roots = m.scenes[scene].nodes;
  else
    for (int i = 0; i < nn; ++i)
      if (c.node_parent[i] < 0) roots.push_back(i);
  std::vector<int> stack(roots.rbegin(), roots.rend());
  std::vector<bool> visited(nn, false);
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    if (i < 0 || i >= nn || visited[i]) continue;
    visited[i] = true;
    c.traversal.push_back(i);
    const auto& ch = m.nodes[i].children;
    for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.push_back(*it);
  }
  // Skins.
  for (size_t s = 0; s < m.skins.size(); ++s) {
    const tinygltf::Skin& sk = m.skins[s];
    CharacterSkin cs;
    cs.name = sk.name;
    cs.joints = sk.joints;
    cs.inverse_bind.assign(sk.joints.size(), Eigen::Matrix4d::Identity());
    if (sk.inverseBindMatrices >= 0) {
      Eigen::MatrixXd ib;
      Status st = read_gltf_accessor(m, sk.inverseBindMatrices, &ib);
      if (!st.ok() || ib.cols() != 16 || ib.rows() < static_cast<Eigen::Index>(sk.joints.size())) {
        r.status = Status::error(StatusCode::ParseError, "skin " + std::to_string(s) + ": bad inverseBindMatrices accessor");
        return r;
      }
      for (size_t j = 0; j < sk.joints.size(); ++j)
        for (int k = 0; k < 16; ++k) cs.inverse_bind[j](k % 4, k / 4) = ib(j, k);
    }
    for (int j : cs.joints)
      if (j < 0 || j >= nn) {
        r.status = Status::error(StatusCode::ParseError, "skin " + std::to_string(s) + " names a missing joint node");
        return r;
      }
    c.skins.push_back(std::move(cs));
  }
  // Animation clips (T/R/S channels).
  for (size_t a = 0; a < m.animations.size(); ++a) {
    const tinygltf::Animation& an = m.animations[a];
    AnimationClip clip;
    clip.name = an.name.empty() ? "animation" + std::to_string(a) : an.name;
    clip.start = 1e300;
    clip.end = -1e300;
    for (const tinygltf::AnimationChannel& ch : an.channels) {
      AnimationChannel out;
      if (ch.target_path == "translation") out.path = AnimationChannel::Path::Translation;
      else if (ch.target_path == "rotation") out.path = AnimationChannel::Path::Rotation;
      else if (ch.target_path == "scale") out.path = AnimationChannel::Path::Scale;
      else continue;  // morph weights do not move the surface we retarget
      if (ch.target_node < 0 || ch.target_node >= nn || ch.sampler < 0 || ch.sampler >= static_cast<int>(an.samplers.size()))
        continue;
      const tinygltf::AnimationSampler& sm = an.samplers[ch.sampler];
      out.node = ch.target_node;
      out.interpolation = sm.interpolation == "STEP"          ? AnimationChannel::Interpolation::Step
                          : sm.interpolation == "CUBICSPLINE" ? AnimationChannel::Interpolation::CubicSpline
                                                              : AnimationChannel::Interpolation::Linear;
      Eigen::MatrixXd in, val;
      Status s1 = read_gltf_accessor(m, sm.input, &in), s2 = read_gltf_accessor(m, sm.output, &val);
      const int dims = out.path == AnimationChannel::Path::Rotation ? 4 : 3;
      const int per_key = out.interpolation == AnimationChannel::Interpolation::CubicSpline ? 3 : 1;
      if (!s1.ok() || !s2.ok() || in.cols() != 1 || in.rows() == 0 || val.cols() != dims || val.rows() != per_key * in.rows()) {
        r.status = Status::error(StatusCode::ParseError, "animation '" + clip.name + "': bad sampler accessors");
        return r;
      }
      out.times = in.col(0);
      out.values = val;
      for (int k = 1; k < out.times.size(); ++k)
        if (!(out.times[k] >= out.times[k - 1])) {
          r.status = Status::error(StatusCode::ParseError, "animation '" + clip.name + "': key times are not ascending");
          return r;
        }
      clip.start = std::min(clip.start, out.times[0]);
      clip.end = std::max(clip.end, out.times[out.times.size() - 1]);
      clip.channels.push_back(std::move(out));
    }
    if (clip.channels.empty()) {
      r.warnings.push_back("animation '" + clip.name + "' has no node channels and is ignored");
      continue;
    }
    c.clips.push_back(std::move(clip));
  }
  // Surface parts.
  struct Candidate { CharacterPart part; Eigen::MatrixXi F; };
  std::vector<Candidate> cands;
  int skinned_vertices = 0, all_vertices = 0;
  for (int ni : c.traversal) {
    const tinygltf::Node& node = m.nodes[ni];
    if (node.mesh < 0 || node.mesh >= static_cast<int>(m.meshes.size())) continue;
    const tinygltf::Mesh& mesh = m.meshes[node.mesh];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      if (prim.mode != -1 && prim.mode != TINYGLTF_MODE_TRIANGLES) continue;
      auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end()) continue;
      Candidate cd;
      CharacterPart& p = cd.part;
      p.node = ni;
      p.mesh = node.mesh;
      p.primitive = static_cast<int>(pi);
      Status st = read_gltf_accessor(m, pos->second, &p.local);
      if (!st.ok() || p.local.cols() != 3) {
        r.status = Status::error(StatusCode::ParseError, "mesh " + std::to_string(node.mesh) + ": bad POSITION");
        return r;
      }
      p.num_vertices = static_cast<int>(p.local.rows());
      if (prim.indices >= 0) {
        Eigen::MatrixXd idx;
        st = read_gltf_accessor(m, prim.indices, &idx);
        if (!st.ok() || idx.cols() != 1 || idx.rows() % 3 != 0) {
          r.status = Status::error(StatusCode::ParseError, "mesh " + std::to_string(node.mesh) + ": bad indices");
          return r;
        }
        cd.F.resize(idx.rows() / 3, 3);
        for (int f = 0; f < cd.F.rows(); ++f)
          for (int k = 0; k < 3; ++k) cd.F(f, k) = static_cast<int>(idx(3 * f + k, 0));
      } else {
        cd.F.resize(p.num_vertices / 3, 3);
        for (int f = 0; f < cd.F.rows(); ++f)
          for (int k = 0; k < 3; ++k) cd.F(f, k) = 3 * f + k;
      }
      if (cd.F.size() > 0 && (cd.F.minCoeff() < 0 || cd.F.maxCoeff() >= p.num_vertices)) {
        r.status = Status::error(StatusCode::ParseError, "mesh " + std::to_string(node.mesh) + ": index out of range");
        return r;
      }
      if (node.skin >= 0 && node.skin < static_cast<int>(c.skins.size()) && prim.attributes.count("JOINTS_0") &&
          prim.attributes.count("WEIGHTS_0")) {
        p.skin = node.skin;
        std::vector<Eigen::MatrixXd> J, W;
        for (int set = 0;; ++set) {
          auto ja = prim.attributes.find("JOINTS_" + std::to_string(set));
          auto wa = prim.attributes.find("WEIGHTS_" + std::to_string(set));
          if (ja == prim.attributes.end() || wa == prim.attributes.end()) break;
          Eigen::MatrixXd j, w;
          if (!read_gltf_accessor(m, ja->second, &j).ok() || !read_gltf_accessor(m, wa->second, &w).ok() ||
              j.rows() != p.num_vertices || w.rows() != p.num_vertices || j.cols() != 4 || w.cols() != 4) {
            r.status = Status::error(StatusCode::ParseError, "mesh " + std::to_string(node.mesh) + ": bad JOINTS/WEIGHTS");
            return r;
          }
          J.push_back(j);
          W.push_back(w);
        }
        const int K = 4 * static_cast<int>(J.size());
        p.joints.resize(p.num_vertices, K);
        p.weights.resize(p.num_vertices, K);
        const int nj = static_cast<int>(c.skins[p.skin].joints.size());
        for (int v = 0; v < p.num_vertices; ++v) {
          double sum = 0;
          for (size_t s = 0; s < J.size(); ++s)
            for (int k = 0; k < 4; ++k) {
              const int slot = static_cast<int>(J[s](v, k));
              double w = W[s](v, k);
              if (slot < 0 || slot >= nj) {
                if (w != 0) {
                  r.status = Status::error(StatusCode::ParseError, "mesh " + std::to_string(node.mesh) +
                                                                       ": JOINTS index beyond the skin's joints");
                  return r;
                }
                w = 0;
              }
              p.joints(v, 4 * s + k) = std::max(0, std::min(slot, nj - 1));
              p.weights(v, 4 * s + k) = w;
              sum += w;
            }
          // The spec asks for normalised weights; exporters round, so renormalise.
          if (sum > 0) p.weights.row(v) /= sum;
          else {
            p.weights.row(v).setZero();
            p.weights(v, 0) = 1;
          }
        }
        skinned_vertices += p.num_vertices;
      }
      all_vertices += p.num_vertices;
      cands.push_back(std::move(cd));
    }
  }
  if (cands.empty()) {
    r.status = Status::error(StatusCode::InvalidMesh, "'" + asset.source_name + "' has no triangle meshes");
    return r;
  }
  bool skinned_only = opt.surface == SurfaceSelection::SkinnedOnly ||
                      (opt.surface == SurfaceSelection::Auto && 2 * skinned_vertices >= all_vertices && skinned_vertices > 0);
  std::vector<int> vertices_of_skin(c.skins.size(), 0);
  int nv = 0, nf = 0;
  for (Candidate& cd : cands) {
    if (skinned_only && cd.part.skin < 0) continue;
    cd.part.first_vertex = nv;
    cd.part.first_face = nf;
    cd.part.num_faces = static_cast<int>(cd.F.rows());
    nv += cd.part.num_vertices;
    nf += cd.part.num_faces;
    if (cd.part.skin >= 0) vertices_of_skin[cd.part.skin] += cd.part.num_vertices;
    c.parts.push_back(cd.part);
  }
  if (skinned_only && static_cast<int>(c.parts.size()) < static_cast<int>(cands.size()))
    r.warnings.push_back(std::to_string(cands.size() - c.parts.size()) +
                         " unskinned primitives (props parented to joints) are not part of the character surface");
  c.F.resize(nf, 3);
  {
    size_t ci = 0;
    for (const Candidate& cd : cands) {
      if (skinned_only && cd.part.skin < 0) continue;
      const CharacterPart& p = c.parts[ci++];
      c.F.middleRows(p.first_face, p.num_faces) = cd.F.array() + p.first_vertex;
    }
  }
  for (size_t s = 0; s < c.skins.size(); ++s)
    if (vertices_of_skin[s] > 0 && (c.main_skin < 0 || vertices_of_skin[s] > vertices_of_skin[c.main_skin]))
      c.main_skin = static_cast<int>(s);
  if (c.main_skin < 0 && !c.skins.empty()) c.main_skin = 0;
  c.V_rest = pose_at(c, -1, 0);
  if (!c.V_rest.allFinite()) {
    r.status = Status::error(StatusCode::InvalidMesh, "the rest pose of '" + asset.source_name + "' is not finite");
    return r;
  }
  return r;
}

Matrix4dList node_world_matrices(const AnimatedCharacter& c, int clip, double t) {
  using namespace gltf_anim_detail;
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

}  // namespace mm::io
