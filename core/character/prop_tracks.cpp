#include "character/prop_tracks.h"

#include <map>

#include "linalg/polar.h"
#include "linalg/rigid_fit.h"

namespace mm {

std::vector<NodeTrack> prop_tracks(const AnimatedCharacter& c, const std::vector<Eigen::MatrixXd>& frames) {
  std::vector<NodeTrack> tracks;
  const int nn = static_cast<int>(c.node_names.size());
  if (frames.empty() || static_cast<int>(c.node_mesh.size()) != nn) return tracks;
  std::vector<bool> is_joint(nn, false), is_surface(nn, false);
  for (const CharacterSkin& sk : c.skins)
    for (int j : sk.joints)
      if (j >= 0 && j < nn) is_joint[j] = true;
  for (const CharacterPart& p : c.parts) is_surface[p.node] = true;
  auto joint_ancestor = [&](int n) {
    int a = c.node_parent[n];
    while (a >= 0 && !is_joint[a]) a = c.node_parent[a];
    return a;
  };
  // Joints with a surface part below them cannot move (the part's morph targets are relative to
  // its rest placement).
  std::vector<bool> carries_surface(nn, false);
  for (const CharacterPart& p : c.parts)
    for (int a = c.node_parent[p.node]; a >= 0; a = c.node_parent[a]) carries_surface[a] = true;
  // Vertices each joint dominates (largest skin weight; rigid surface parts: their joint ancestor).
  std::vector<std::vector<int>> dominated(nn);
  for (const CharacterPart& p : c.parts) {
    for (int v = 0; v < p.num_vertices; ++v) {
      int node = -1;
      if (p.skin >= 0 && p.weights.rows() == p.num_vertices && p.weights.cols() > 0) {
        Eigen::Index k = 0;
        p.weights.row(v).maxCoeff(&k);
        const int slot = p.joints(v, k);
        if (slot >= 0 && slot < static_cast<int>(c.skins[p.skin].joints.size())) node = c.skins[p.skin].joints[slot];
      } else {
        node = is_joint[p.node] ? p.node : joint_ancestor(p.node);
      }
      if (node >= 0 && node < nn) dominated[node].push_back(p.first_vertex + v);
    }
  }
  std::map<int, int> track_of;  // joint node → index in tracks
  for (int n : c.traversal) {
    if (c.node_mesh[n] < 0 || is_surface[n]) continue;
    const int a = joint_ancestor(n);
    if (a < 0 || carries_surface[a] || c.node_has_matrix[a]) continue;
    auto it = track_of.find(a);
    if (it == track_of.end()) {
      int anchor = a;
      while (anchor >= 0 && dominated[anchor].size() < 3) anchor = joint_ancestor(anchor);
      if (anchor < 0) continue;
      NodeTrack t;
      t.node = a;
      t.anchor_joint = anchor;
      t.anchor_vertices = dominated[anchor];
      it = track_of.emplace(a, static_cast<int>(tracks.size())).first;
      tracks.push_back(std::move(t));
    }
    tracks[it->second].props.push_back(n);
  }
  if (tracks.empty()) return tracks;
  const Matrix4dList rest = node_world_matrices(c, -1, 0);
  Matrix4dList local_rest(nn);
  for (int n = 0; n < nn; ++n) {
    const int p = c.node_parent[n];
    local_rest[n] = p >= 0 ? Eigen::Matrix4d(rest[p].inverse() * rest[n]) : rest[n];
  }
  for (NodeTrack& t : tracks) {
    const int m = static_cast<int>(t.anchor_vertices.size());
    Eigen::MatrixXd X(m, 3);
    for (int i = 0; i < m; ++i) X.row(i) = c.V_rest.row(t.anchor_vertices[i]);
    for (const Eigen::MatrixXd& Vf : frames) {
      Eigen::MatrixXd Y(m, 3);
      for (int i = 0; i < m; ++i) Y.row(i) = Vf.row(t.anchor_vertices[i]);
      // The best rigid fit X → Y (Kabsch, linalg/rigid_fit.h).
      const RigidFit fit = fit_rigid(X, Y);
      Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
      M.topLeftCorner<3, 3>() = fit.R;
      M.topRightCorner<3, 1>() = fit.t;
      t.world.push_back(M * rest[t.node]);
    }
  }
  // Local transforms: a tracked joint may hang below another tracked joint (helmet on the head,
  // cape on the chest), so walk the hierarchy per frame.
  std::vector<int> tracked(nn, -1);
  for (size_t k = 0; k < tracks.size(); ++k) tracked[tracks[k].node] = static_cast<int>(k);
  for (size_t f = 0; f < frames.size(); ++f) {
    Matrix4dList world(nn, Eigen::Matrix4d::Identity());
    std::vector<bool> done(nn, false);
    for (int n : c.traversal) {  // parents before children
      const int p = c.node_parent[n];
      const Eigen::Matrix4d parent = p >= 0 && done[p] ? world[p] : Eigen::Matrix4d::Identity();
      if (tracked[n] >= 0) {
        NodeTrack& t = tracks[tracked[n]];
        world[n] = t.world[f];
        const Eigen::Matrix4d L = parent.inverse() * world[n];
        // L = T · R · S with the rest scale S kept: R = polar(L₃ S⁻¹).
        const Eigen::Vector3d s = c.node_s[n];
        Eigen::Matrix3d RS = L.topLeftCorner<3, 3>();
        for (int k = 0; k < 3; ++k) RS.col(k) /= (s[k] != 0 ? s[k] : 1.0);
        Eigen::Quaterniond q(polar_decomposition(RS).R);
        q.normalize();
        if (!t.rotation.empty() && q.coeffs().dot(t.rotation.back().coeffs()) < 0) q.coeffs() *= -1;
        t.translation.push_back(L.topRightCorner<3, 1>());
        t.rotation.push_back(q);
      } else {
        world[n] = parent * local_rest[n];
      }
      done[n] = true;
    }
  }
  return tracks;
}

}  // namespace mm
