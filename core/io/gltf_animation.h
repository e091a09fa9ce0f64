// glTF skins and animations: an animated character (node hierarchy, skins, clips, the surface
// primitives with their influences), evaluated at any time by linear blend skinning, and the
// writer of a retargeted animation as a GLB with one morph target per frame.
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

#include "common/status.h"
#include "io/asset.h"
#include "retarget/joint_set.h"
#include "retarget/lbs_baseline.h"

namespace mm::io {

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

enum class SurfaceSelection {
  Auto,         // skinned primitives when they hold at least half of the vertices (KayKit: the
                // body, not the helmet and weapons parented to joints), otherwise all (RobotExpressive)
  SkinnedOnly,  // skinned primitives only
  All,          // every triangle primitive of the scene
};

struct CharacterOptions {
  SurfaceSelection surface = SurfaceSelection::Auto;
};

struct CharacterResult {
  Status status;                     // Unsupported for non-glTF assets; InvalidMesh with no triangles
  AnimatedCharacter character;
  std::vector<std::string> warnings;
};

// Reads the character from a loaded glTF/GLB asset (its kept tinygltf document).
CharacterResult animated_character(const Asset& asset, const CharacterOptions& opt = {});

using Matrix4dList = mm::Matrix4dList;

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
// Per node: world(t) · world(rest)⁻¹ (maps the rest surface to the posed one).
Matrix4dList node_motions(const AnimatedCharacter& c, const Matrix4dList& world);

// Frame times: from `start` to `end` (clip range when both are < 0) at `fps`, both ends included.
std::vector<double> frame_times(const AnimationClip& clip, double fps, double start = -1, double end = -1);

// Props: meshes of a glTF target that are not part of its surface (weapons, helmets, capes)
// hanging under a joint node. The retargeted surface moves through morph targets, so a prop
// would stay where it is; instead its nearest joint ancestor gets a rigid motion per frame: the
// best rigid fit (Kabsch) from the rest surface to the frame of the vertices that joint
// dominates in the skin (or, when it dominates none, its nearest ancestor that does). A joint
// is left alone when a surface part hangs below it or when it is given by a matrix.
struct NodeTrack {
  int node = -1;                                   // the joint node that is animated
  std::vector<int> props;                          // prop nodes that follow it
  int anchor_joint = -1;                           // joint whose vertices define the motion
  std::vector<int> anchor_vertices;                // rows of V_rest
  std::vector<Eigen::Vector3d> translation;        // per frame, local T
  std::vector<Eigen::Quaterniond, Eigen::aligned_allocator<Eigen::Quaterniond>> rotation;  // per frame, local R
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> world;          // per frame, world matrix
};
std::vector<NodeTrack> prop_tracks(const AnimatedCharacter& c, const std::vector<Eigen::MatrixXd>& frames);

struct MorphAnimationOptions {
  std::string animation_name = "retarget";  // name of the written animation
  bool normals = true;                      // also write NORMAL deltas (lit correctly while playing)
  bool props_follow = true;                 // animate the joints that carry props (prop_tracks)
};

// The target with its animation: a GLB whose surface meshes carry one morph target per frame and
// one animation driving the morph weights (LINEAR, so playback interpolates between frames).
// glTF targets keep everything (materials, textures, other nodes); their surface parts lose
// their skin (the motion is in the morph targets) and their original animations are removed
// (they would move the skeleton under the morphs). Other targets (OBJ/OFF/PLY) become a plain
// single-mesh glTF. `frames`: per frame, positions in the target surface layout — V_rest of
// `target_character` for glTF targets, asset.V_raw otherwise. `times`: seconds, ascending.
Status write_morph_animation(const Asset& target, const AnimatedCharacter* target_character,
                             const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                             std::vector<uint8_t>* glb, const MorphAnimationOptions& opt = {});

}  // namespace mm::io
