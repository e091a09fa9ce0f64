// Write-back of a loaded glTF document with new positions (io-internal).
//
// Only primitives with moved vertices change: each gets new POSITION (and, with
// recompute_normals, NORMAL) accessors in new bufferViews appended to buffer 0, in the node's
// local space (inverse world transform), with min/max. Everything else (accessors, materials,
// textures, images, nodes, skins, animations, extras) is written back as loaded; the old
// accessors stay (unused), so no index in the document changes.
//
// A mesh used by several nodes: the first instance (scene order) writes into the mesh; a later
// instance whose new local positions differ (beyond 1e-6 of the bbox diagonal) gets a copy of
// the mesh (appended to meshes, node.mesh redirected) with its own accessors.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "io/asset.h"
#include "io/gltf_serialize.h"

namespace mm::io {

// V_raw_out: #V_raw by 3 world positions (unmoved vertices hold asset.V_raw); moved: per raw
// vertex, 1 when it moved. target: Gltf or Glb; sidecar_stem: see serialize_gltf.
Status save_gltf_document(const Asset& asset, const Eigen::MatrixXd& V_raw_out, const std::vector<char>& moved,
                          Format target, const SaveOptions& opt, const std::string& sidecar_stem, GltfFiles* out);

}  // namespace mm::io

namespace mm::io {

// save_asset_with_mesh for a glTF document (see io/asset.h): the document with the loaded
// triangle primitives replaced by one new primitive (V, F in world space) under a new root node.
Status save_gltf_with_mesh(const Asset& asset, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, Format target,
                           const std::string& sidecar_stem, GltfFiles* out);

}  // namespace mm::io
