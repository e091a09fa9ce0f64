// glTF skins and animations: reads an animated character (core/character/animated_character.h)
// from a loaded glTF/GLB asset, and writes a retargeted animation as a GLB with one morph target
// per frame. Formats only: the character's evaluation lives in core/character, the props' rigid
// motions (character/prop_tracks.h) are computed by the caller and passed in.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/StdVector>

#include "common/status.h"
#include "io/asset.h"
#include "character/animated_character.h"
#include "character/prop_tracks.h"

namespace mm::io {

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

enum class MorphExport {
  Auto,     // Compact when there are more than compact_min_frames frames, else Frames
  Frames,   // one morph target per frame (exact up to float storage; size grows with the clip)
  Compact,  // mean + K principal components as morph targets, K weights per frame (see below)
};

struct MorphAnimationOptions {
  std::string animation_name = "retarget";  // name of the written animation
  bool normals = true;                      // also write NORMAL deltas (lit correctly while playing)
  MorphExport layout = MorphExport::Auto;   // how the frames become morph targets
  int compact_min_frames = 60;              // Auto: Compact above this many frames (2 s at 30 fps)
  double tolerance = 1e-3;                  // Compact: max distance of any vertex of any frame from
                                            // the frame, × the target's size (largest side of the
                                            // rest bounding box; the height of a standing character)
  int max_components = 64;                  // Compact: K at most; above it the tolerance is not met
  bool quantize = true;                     // Compact: components as SHORT (KHR_mesh_quantization)
                                            // when the bound still holds with them, else FLOAT
  int normal_components = 32;               // Compact with normals: NORMAL deltas fitted for the
                                            // first this-many components; the others share one zero
                                            // NORMAL accessor (FLOAT normals cost 12 bytes per vertex
                                            // and component, 1.5× the SHORT positions)
};

// What the writer chose and measured (for the CLI, the batch metrics and the tests).
struct MorphAnimationReport {
  bool compact = false;     // the Compact layout was written
  int targets = 0;          // morph targets written per surface primitive (Frames: #frames;
                            // Compact: 1 + K, the mean and the components)
  int components = 0;       // Compact: K
  double max_error = 0;     // Compact: max vertex distance to the frames / size, measured on the
                            // stored data as a viewer decodes it (float, SHORT and weights)
  double size = 0;          // the target's size the tolerance is relative to
  bool capped = false;      // Compact: the tolerance was not met with max_components
  bool quantized = false;   // Compact: components stored as SHORT with KHR_mesh_quantization
  double normal_error = 0;  // Compact with normals: max angle (radians) between a frame's normal and
                            // the normal the morphs give (both normalised)
};

// The target with its animation: a GLB whose surface meshes carry morph targets and one animation
// driving the morph weights (LINEAR, so playback interpolates between frames).
// Frames layout: one morph target per frame, weight 1 at its frame.
// Compact layout (character/morph_basis.h): target 0 is the mean displacement of the clip (FLOAT,
// weight 1 in every key; mesh.weights stay 0, so the document's static pose is the target's rest
// pose, which the props' joints also rest in), targets 1..K the principal components. Each
// component's weights w_fk (range [lo_k, lo_k + span_k] over the frames) are stored as
// t_fk·δ_k with t in [0, 1]: lo_k·u_k joins the mean, and span_k·u_k is stored as integers
// q_k = round(span_k·u_k / δ_k) (SHORT, |q| ≤ 32767, δ_k = max|span_k·u_k| / 32767 in the node's
// space; with FLOAT storage δ_k = 1). So the weights stay in [0, 1] (Blender clamps shape-key
// values to their slider range, [0, 1] unless its importer widens it, which Blender 3.4 does from
// the first key only). K is the smallest with every vertex of every frame within the tolerance,
// measured on the stored data (quantization included); if SHORT storage breaks the bound, FLOAT is used instead.
// NORMAL deltas (opt.normals): per target, the least-squares fit of the frames' normal deltas on the
// same weights (FLOAT; three.js uses them, Blender recomputes normals from the shape anyway), for the
// first opt.normal_components components (the leading ones carry most of the motion).
// glTF targets keep everything (materials, textures, other nodes); their surface parts lose
// their skin (the motion is in the morph targets) and their original animations are removed
// (they would move the skeleton under the morphs). Other targets (OBJ/OFF/PLY) become a plain
// single-mesh glTF. `frames`: per frame, positions in the target surface layout — V_rest of
// `target_character` for glTF targets, asset.V_raw otherwise. `times`: seconds, ascending.
// `prop_tracks`: translation/rotation channels for joints that carry props (glTF targets only;
// from character/prop_tracks.h, one entry per frame), written into the same animation.
Status write_morph_animation(const Asset& target, const AnimatedCharacter* target_character,
                             const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                             std::vector<uint8_t>* glb, const MorphAnimationOptions& opt = {},
                             const std::vector<NodeTrack>& prop_tracks = {}, MorphAnimationReport* report = nullptr);

}  // namespace mm::io
