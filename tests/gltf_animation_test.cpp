// Tests of io/gltf_animation.h: skins, clips and LBS evaluation checked against an independent
// first-principles evaluation (written here from the glTF spec, straight from the tinygltf
// model), rest pose, multi-part characters, and the morph-target animation writer.
#include <gtest/gtest.h>

#include <cmath>

#include "io/asset.h"
#include "io/gltf_accessor.h"
#include "io/gltf_animation.h"
#include "mesh/mesh.h"
#include "retarget/lbs_baseline.h"
#include "test_support.h"

namespace {

using mm::AnimatedCharacter;

struct Loaded {
  mm::io::LoadResult asset;
  mm::io::CharacterResult character;
};

Loaded load(const std::string& rel, mm::io::SurfaceSelection sel = mm::io::SurfaceSelection::Auto) {
  Loaded l;
  l.asset = mm::io::load_asset(mm::test::data_path(rel));
  if (l.asset.status.ok()) {
    mm::io::CharacterOptions o;
    o.surface = sel;
    l.character = mm::io::animated_character(l.asset.asset, o);
  }
  return l;
}

// ---- An independent evaluation from the glTF spec, reading the tinygltf model directly ----
Eigen::MatrixXd accessor(const tinygltf::Model& m, int index) {
  Eigen::MatrixXd out;
  EXPECT_TRUE(mm::io::read_gltf_accessor(m, index, &out).ok());
  return out;
}

Eigen::Matrix4d compose(const Eigen::Vector3d& t, const Eigen::Vector4d& q_xyzw, const Eigen::Vector3d& s) {
  // Rotation matrix of a unit quaternion written out (no Eigen::Quaternion): glTF stores x y z w.
  const Eigen::Vector4d q = q_xyzw / q_xyzw.norm();
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  Eigen::Matrix3d R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
       2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
       2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y);
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M.topLeftCorner<3, 3>() = R * s.asDiagonal();
  M.topRightCorner<3, 1>() = t;
  return M;
}

Eigen::Vector4d slerp_xyzw(Eigen::Vector4d a, Eigen::Vector4d b, double u) {
  double d = a.dot(b);
  if (d < 0) {
    b = -b;
    d = -d;
  }
  if (d > 0.9995) return ((1 - u) * a + u * b).normalized();
  const double th = std::acos(d);
  return (std::sin((1 - u) * th) * a + std::sin(u * th) * b) / std::sin(th);
}

// Skinned position of vertex v of the first skinned primitive at time t of animation `anim`.
Eigen::Vector3d first_principles(const tinygltf::Model& m, int anim, double t, int v) {
  const int nn = static_cast<int>(m.nodes.size());
  std::vector<Eigen::Vector3d> T(nn, Eigen::Vector3d::Zero()), S(nn, Eigen::Vector3d::Ones());
  std::vector<Eigen::Vector4d> R(nn, Eigen::Vector4d(0, 0, 0, 1));
  for (int i = 0; i < nn; ++i) {
    const auto& n = m.nodes[i];
    if (n.translation.size() == 3) T[i] << n.translation[0], n.translation[1], n.translation[2];
    if (n.scale.size() == 3) S[i] << n.scale[0], n.scale[1], n.scale[2];
    if (n.rotation.size() == 4) R[i] << n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3];
  }
  for (const auto& ch : m.animations[anim].channels) {
    const auto& sm = m.animations[anim].samplers[ch.sampler];
    const Eigen::MatrixXd in = accessor(m, sm.input), out = accessor(m, sm.output);
    int k = 0;
    while (k + 2 < in.rows() && in(k + 1, 0) <= t) ++k;
    double u = (t - in(k, 0)) / (in(k + 1, 0) - in(k, 0));
    u = std::min(1.0, std::max(0.0, u));
    if (ch.target_path == "rotation") R[ch.target_node] = slerp_xyzw(out.row(k).transpose(), out.row(k + 1).transpose(), u);
    else if (ch.target_path == "translation") T[ch.target_node] = (1 - u) * out.row(k).transpose() + u * out.row(k + 1).transpose();
    else if (ch.target_path == "scale") S[ch.target_node] = (1 - u) * out.row(k).transpose() + u * out.row(k + 1).transpose();
  }
  std::vector<int> parent(nn, -1);
  for (int i = 0; i < nn; ++i)
    for (int c : m.nodes[i].children) parent[c] = i;
  auto local = [&](int n) {
    if (m.nodes[n].matrix.size() == 16) {  // column-major 4x4
      Eigen::Matrix4d M;
      for (int e = 0; e < 16; ++e) M(e % 4, e / 4) = m.nodes[n].matrix[e];
      return M;
    }
    return compose(T[n], R[n], S[n]);
  };
  auto world = [&](int i) {
    Eigen::Matrix4d W = Eigen::Matrix4d::Identity();
    for (int n = i; n >= 0; n = parent[n]) W = local(n) * W;
    return W;
  };
  int node = 0;
  while (m.nodes[node].skin < 0) ++node;
  const auto& prim = m.meshes[m.nodes[node].mesh].primitives[0];
  const auto& skin = m.skins[m.nodes[node].skin];
  const Eigen::MatrixXd P = accessor(m, prim.attributes.at("POSITION"));
  const Eigen::MatrixXd J = accessor(m, prim.attributes.at("JOINTS_0"));
  const Eigen::MatrixXd W = accessor(m, prim.attributes.at("WEIGHTS_0"));
  const Eigen::MatrixXd IB = accessor(m, skin.inverseBindMatrices);
  Eigen::Vector4d p(P(v, 0), P(v, 1), P(v, 2), 1), acc = Eigen::Vector4d::Zero();
  const double wsum = W.row(v).sum();
  for (int k = 0; k < 4; ++k) {
    const int slot = static_cast<int>(J(v, k));
    Eigen::Matrix4d ib;
    for (int e = 0; e < 16; ++e) ib(e % 4, e / 4) = IB(slot, e);
    acc += W(v, k) / wsum * (world(skin.joints[slot]) * ib * p);
  }
  return acc.head<3>();
}

}  // namespace

TEST(GltfAnimation, CesiumManMatchesFirstPrinciples) {
  Loaded l = load("anim/CesiumMan/CesiumMan.glb");
  ASSERT_TRUE(l.asset.status.ok()) << l.asset.status.message;
  ASSERT_TRUE(l.character.status.ok()) << l.character.status.message;
  const AnimatedCharacter& c = l.character.character;
  ASSERT_EQ(c.clips.size(), 1u);
  ASSERT_EQ(c.parts.size(), 1u);
  const tinygltf::Model& m = *mm::io::gltf_model(l.asset.asset);
  for (double t : {0.05, 0.61, 1.234, 1.99}) {
    const Eigen::MatrixXd V = mm::pose_at(c, 0, t);
    for (int v : {0, 777, 1500, 2345, 3272}) {
      const Eigen::Vector3d ref = first_principles(m, 0, t, v);
      EXPECT_LT((V.row(v).transpose() - ref).norm(), 1e-5) << "t " << t << " vertex " << v;
    }
  }
}

TEST(GltfAnimation, FoxMatchesFirstPrinciples) {
  Loaded l = load("anim/Fox/glTF-Binary/Fox.glb");
  ASSERT_TRUE(l.character.status.ok()) << l.character.status.message;
  const AnimatedCharacter& c = l.character.character;
  ASSERT_EQ(c.clips.size(), 3u);
  const tinygltf::Model& m = *mm::io::gltf_model(l.asset.asset);
  for (int clip : {0, 1, 2})
    for (double t : {0.1, 0.5}) {
      const Eigen::MatrixXd V = mm::pose_at(c, clip, t);
      for (int v : {0, 500, 1000, 1727}) {
        const Eigen::Vector3d ref = first_principles(m, clip, t, v);
        // Fox is ~100 units: 1e-5 relative.
        EXPECT_LT((V.row(v).transpose() - ref).norm(), 1e-3) << c.clips[clip].name << " t " << t << " vertex " << v;
      }
    }
}

TEST(GltfAnimation, RestPoseReproducesMesh) {
  for (const char* f : {"anim/CesiumMan/CesiumMan.glb", "anim/Fox/glTF-Binary/Fox.glb"}) {
    Loaded l = load(f);
    ASSERT_TRUE(l.character.status.ok()) << f;
    const AnimatedCharacter& c = l.character.character;
    // Single-primitive characters: the surface layout is the asset's raw layout.
    ASSERT_EQ(c.V_rest.rows(), l.asset.asset.V_raw.rows());
    const double diag = mm::bounding_box_diagonal(c.V_rest);
    EXPECT_LT((c.V_rest - l.asset.asset.V_raw).cwiseAbs().maxCoeff(), 1e-5 * diag) << f;
  }
}

TEST(GltfAnimation, MultiPartCharactersNeedNoWelding) {
  Loaded k = load("anim/KayKit/Knight.glb");
  ASSERT_TRUE(k.character.status.ok());
  // Auto: the 6 skinned body primitives; the helmet, cape and weapons (rigid props) are left out.
  EXPECT_EQ(k.character.character.parts.size(), 6u);
  Loaded r = load("anim/RobotExpressive/RobotExpressive.glb");
  ASSERT_TRUE(r.character.status.ok());
  // Auto: mostly rigid parts parented to bones, so everything is the surface.
  EXPECT_EQ(r.character.character.parts.size(), 19u);
  for (const Loaded* l : {&k, &r}) {
    const AnimatedCharacter& c = l->character.character;
    int nv = 0;
    for (const auto& p : c.parts) nv += p.num_vertices;
    EXPECT_EQ(nv, c.V_rest.rows());  // raw layout, nothing merged
    const Eigen::MatrixXd V = mm::pose_at(c, 1, 0.3);
    EXPECT_TRUE(V.allFinite());
    // LBS of the rest surface by node motions reproduces the evaluation (the baseline's premise).
    const auto world = mm::node_world_matrices(c, 1, 0.3);
    const Eigen::MatrixXd L = mm::linear_blend_skinning(c.V_rest, mm::character_skin_weights(c), mm::node_motions(c, world));
    EXPECT_LT((L - V).cwiseAbs().maxCoeff(), 1e-6 * mm::bounding_box_diagonal(V));
  }
}

TEST(GltfAnimation, StepAndCubicSplineSamplers) {
  AnimatedCharacter c;  // one node, hand-made clip
  c.node_names = {"n"};
  c.node_parent = {-1};
  c.node_has_matrix = {false};
  c.node_matrix.assign(1, Eigen::Matrix4d::Identity());
  c.node_t = {Eigen::Vector3d::Zero()};
  c.node_s = {Eigen::Vector3d::Ones()};
  c.node_r.assign(1, Eigen::Quaterniond::Identity());
  c.traversal = {0};
  mm::AnimationClip clip;
  mm::AnimationChannel step;
  step.node = 0;
  step.path = mm::AnimationChannel::Path::Translation;
  step.interpolation = mm::AnimationChannel::Interpolation::Step;
  step.times = Eigen::Vector2d(0, 1);
  step.values.resize(2, 3);
  step.values << 1, 2, 3, 4, 5, 6;
  mm::AnimationChannel cubic;  // scale: in-tangent, value, out-tangent per key
  cubic.node = 0;
  cubic.path = mm::AnimationChannel::Path::Scale;
  cubic.interpolation = mm::AnimationChannel::Interpolation::CubicSpline;
  cubic.times = Eigen::Vector2d(0, 2);
  cubic.values.resize(6, 3);
  cubic.values << 0, 0, 0, 1, 1, 1, 1, 0, 0,   // key 0: value 1, out-tangent (1,0,0)
                  0, 0, 0, 3, 3, 3, 0, 0, 0;   // key 1: value 3, in-tangent 0
  clip.channels = {step, cubic};
  c.clips = {clip};
  const auto W = mm::node_world_matrices(c, 0, 0.5);
  EXPECT_LT((W[0].topRightCorner<3, 1>() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);  // STEP holds key 0
  // Hermite at u = 0.25, dt = 2: (2u³−3u²+1)·1 + (u³−2u²+u)·2·b0 + (−2u³+3u²)·3.
  const double u = 0.25, h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u, h01 = -2 * u * u * u + 3 * u * u;
  const double sx = h00 * 1 + h10 * 2 * 1 + h01 * 3, sy = h00 * 1 + h01 * 3;
  EXPECT_NEAR(W[0](0, 0), sx, 1e-12);
  EXPECT_NEAR(W[0](1, 1), sy, 1e-12);
}

TEST(GltfAnimation, MorphAnimationExportRoundTrip) {
  Loaded fox = load("anim/Fox/glTF-Binary/Fox.glb");
  ASSERT_TRUE(fox.character.status.ok());
  const AnimatedCharacter& c = fox.character.character;
  // Export the Fox's own Walk as morph targets onto the Fox itself: 4 frames.
  std::vector<Eigen::MatrixXd> frames;
  std::vector<double> times;
  for (int k = 0; k < 4; ++k) {
    times.push_back(0.1 * k);
    frames.push_back(mm::pose_at(c, 1, 0.1 * k));
  }
  std::vector<uint8_t> glb;
  ASSERT_TRUE(mm::io::write_morph_animation(fox.asset.asset, &c, frames, times, &glb).ok());
  const mm::io::LoadResult back = mm::io::load_asset_from_memory(glb, mm::io::Format::Glb, "fox_morph.glb");
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  const tinygltf::Model& m = *mm::io::gltf_model(back.asset);
  ASSERT_EQ(m.animations.size(), 1u);
  EXPECT_EQ(m.animations[0].channels[0].target_path, "weights");
  const auto& prim = m.meshes[c.parts[0].mesh].primitives[0];
  ASSERT_EQ(prim.targets.size(), 4u);
  EXPECT_EQ(m.nodes[c.parts[0].node].skin, -1);  // the motion lives in the morphs now
  EXPECT_EQ(m.textures.size(), mm::io::gltf_model(fox.asset.asset)->textures.size());  // materials kept
  // base + target k, through the node's world transform, is frame k.
  const Eigen::MatrixXd base = accessor(m, prim.attributes.at("POSITION"));
  const Eigen::MatrixXd d2 = accessor(m, prim.targets[2].at("POSITION"));
  mm::io::CharacterResult cb = mm::io::animated_character(back.asset);
  ASSERT_TRUE(cb.status.ok());
  const Eigen::Matrix4d W = mm::node_world_matrices(cb.character, -1, 0)[c.parts[0].node];
  for (int v : {0, 100, 1000}) {
    const Eigen::Vector3d p = W.topLeftCorner<3, 3>() * (base.row(v) + d2.row(v)).transpose() + W.topRightCorner<3, 1>();
    EXPECT_LT((p - frames[2].row(v).transpose()).norm(), 1e-3) << v;  // float storage of ~100-unit coordinates
  }
}
