#include "io/gltf_animation.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "io/gltf_accessor.h"
#include "io/gltf_document.h"

namespace mm::io {

CharacterResult animated_character(const Asset& asset, const CharacterOptions& opt) {
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
    if (!read_gltf_inverse_binds(m, sk, &cs.inverse_bind)) {
      r.status = Status::error(StatusCode::ParseError, "skin " + std::to_string(s) + ": bad inverseBindMatrices accessor");
      return r;
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
      if (!gltf_is_triangle_mode(prim.mode)) continue;
      auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end()) continue;
      Candidate cd;
      CharacterPart& p = cd.part;
      p.node = ni;
      p.mesh = node.mesh;
      p.primitive = static_cast<int>(pi);
      GltfTriangles tris;
      const std::string label = "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(pi);
      if (Status st = read_gltf_triangles(m, prim, label, &tris); !st.ok()) {
        r.status = st;
        return r;
      }
      p.local = std::move(tris.P);
      p.num_vertices = static_cast<int>(p.local.rows());
      cd.F = std::move(tris.F);
      if (cd.F.size() > 0 && (cd.F.minCoeff() < 0 || cd.F.maxCoeff() >= p.num_vertices)) {
        r.status = Status::error(StatusCode::ParseError, "mesh " + std::to_string(node.mesh) + ": index out of range");
        return r;
      }
      if (node.skin >= 0 && node.skin < static_cast<int>(c.skins.size()) && prim.attributes.count("JOINTS_0") &&
          prim.attributes.count("WEIGHTS_0")) {
        p.skin = node.skin;
        Eigen::MatrixXd J, W;
        if (!read_gltf_skin_influences(m, prim, p.num_vertices, &J, &W)) {
          r.status = Status::error(StatusCode::ParseError, "mesh " + std::to_string(node.mesh) + ": bad JOINTS/WEIGHTS");
          return r;
        }
        const int K = static_cast<int>(J.cols());
        p.joints.resize(p.num_vertices, K);
        p.weights.resize(p.num_vertices, K);
        const int nj = static_cast<int>(c.skins[p.skin].joints.size());
        for (int v = 0; v < p.num_vertices; ++v) {
          double sum = 0;
          for (int s = 0; s < K / 4; ++s)
            for (int k = 0; k < 4; ++k) {
              const int slot = static_cast<int>(J(v, 4 * s + k));
              double w = W(v, 4 * s + k);
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

}  // namespace mm::io
