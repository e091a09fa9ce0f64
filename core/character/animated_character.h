// An animated character: node hierarchy, skins, clips and the surface primitives with their
// influences (read from glTF by io/gltf_animation.h), evaluated at any time by linear blend
// skinning.
//
// Evaluation follows the glTF 2.0 spec: a node's local transform is its matrix or T·R·S, with
// animation channels replacing T, R or S; LINEAR (slerp for rotations), STEP and CUBICSPLINE
// (Hermite, tangents × key interval) samplers; times outside a channel clamp to its ends. A
// skinned vertex is Σ_k w_k · world(joint_k) · inverseBind_k · p (the mesh node's own transform
// is ignored), with all JOINTS_n/WEIGHTS_n sets (4·n influences); an unskinned primitive follows
// its node's world transform (rigid parts parented to bones).
//
// The character surface (V_rest, F) concatenates the selected primitives in scene traversal
// order; it is a triangle soup (not welded: multi-part characters stay as they are).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/StdVector>

#include "character/joint_set.h"
#include "character/skinning.h"
#include "common/status.h"

namespace mm {

struct AnimationChannel {
  enum class Path { Translation, Rotation, Scale, Weights };
  enum class Interpolation { Linear, Step, CubicSpline };
  int node = -1;
  Path path = Path::Translation;
  Interpolation interpolation = Interpolation::Linear;
  Eigen::VectorXd times;   // #K ascending key times (seconds)
  Eigen::MatrixXd values;  // #K by 3 (T, S) or 4 (R: x y z w); CUBICSPLINE: 3·#K rows (in-tangent, value, out-tangent)
};

struct AnimationClip {
  std::string name;        // glTF name, or "animation<i>" when unnamed
  double start = 0;        // earliest key time
  double end = 0;          // latest key time
  std::vector<AnimationChannel> channels;  // T/R/S channels (weights channels are skipped)
};

struct CharacterSkin {
  std::string name;
  std::vector<int> joints;                                                 // node indices
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> inverse_bind;  // per joint
};

struct CharacterPart {
  int node = -1, mesh = -1, primitive = -1;
  int skin = -1;           // index into skins, -1 for a rigid part (follows its node)
  int first_vertex = 0;    // rows in AnimatedCharacter::V_rest
  int num_vertices = 0;
  int first_face = 0;      // rows in AnimatedCharacter::F
  int num_faces = 0;
  Eigen::MatrixXd local;   // #v by 3 POSITION (mesh space)
  Eigen::MatrixXi joints;  // #v by K joint slots into skins[skin].joints (skinned parts)
  Eigen::MatrixXd weights; // #v by K weights (normalised to sum 1)
};

struct AnimatedCharacter {
  std::vector<std::string> node_names;   // unique: empty or repeated names get "#<index>" appended
  std::vector<int> node_parent;          // -1 for scene roots
  std::vector<bool> node_has_matrix;     // node given by a matrix (cannot be animated)
  std::vector<int> node_mesh;            // mesh index of each node, -1 when it has none
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> node_matrix;  // when has_matrix
  std::vector<Eigen::Vector3d> node_t, node_s;   // rest T and S
  std::vector<Eigen::Quaterniond, Eigen::aligned_allocator<Eigen::Quaterniond>> node_r;  // rest R
  std::vector<int> traversal;            // scene nodes, parents before children
  std::vector<CharacterSkin> skins;
  std::vector<AnimationClip> clips;
  std::vector<CharacterPart> parts;      // the surface parts
  int main_skin = -1;                    // the skin of most surface vertices (defines the joints)
  Eigen::MatrixXd V_rest;                // #V by 3 surface at the rest pose (no animation)
  Eigen::MatrixXi F;                     // #F by 3 over V_rest
};

// World matrices of all nodes at time t of clip `clip` (-1: the rest pose).
Matrix4dList node_world_matrices(const AnimatedCharacter& c, int clip, double t);
// The surface (#V by 3, V_rest layout) for the given node world matrices.
Eigen::MatrixXd posed_vertices(const AnimatedCharacter& c, const Matrix4dList& world);
// Shorthand: the surface at time t of clip (-1: rest).
Eigen::MatrixXd pose_at(const AnimatedCharacter& c, int clip, double t);

// Index of the clip named `name` ("" = the first clip). Not found: InvalidArgument listing the clips.
Status find_clip(const AnimatedCharacter& c, const std::string& name, int* index);

// The main skin's joints at the rest pose: names, world positions, parents (nearest ancestor
// among the skin's joints). Empty when the character has no skin.
JointSet character_joints(const AnimatedCharacter& c);

// Influences of every surface vertex on node motions, for the LBS baseline: index = node,
// weight = skin weight (rigid parts: their node, weight 1). Together with node_motions, LBS of
// V_rest reproduces posed_vertices.
SkinWeights character_skin_weights(const AnimatedCharacter& c);
// The same influences over the rows of J (a character_joints set): each node's weight goes to
// its nearest ancestor (itself included) among J's joints, matched by node name; weights on
// nodes without one get index -1.
SkinWeights joint_skin_weights(const AnimatedCharacter& c, const JointSet& J);
// Per node: world(t) · world(rest)⁻¹ (maps the rest surface to the posed one).
Matrix4dList node_motions(const AnimatedCharacter& c, const Matrix4dList& world);

// Frame times: from `start` to `end` (clip range when both are < 0) at `fps`, both ends included.
std::vector<double> frame_times(const AnimationClip& clip, double fps, double start = -1, double end = -1);

}  // namespace mm
