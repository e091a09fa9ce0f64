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

struct MorphAnimationOptions {
  std::string animation_name = "retarget";  // name of the written animation
  bool normals = true;                      // also write NORMAL deltas (lit correctly while playing)
};

// The target with its animation: a GLB whose surface meshes carry one morph target per frame and
// one animation driving the morph weights (LINEAR, so playback interpolates between frames).
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
                             const std::vector<NodeTrack>& prop_tracks = {});

}  // namespace mm::io
