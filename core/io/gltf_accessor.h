// Bounds-checked reading of glTF accessors (io-internal): every offset, stride and sparse
// index is checked against the buffer it points into, so a malformed file gives ParseError.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "character/skinning.h"
#include "io/gltf_document.h"

namespace mm::io {

// Number of components of an accessor type (SCALAR 1 ... MAT4 16); 0 when unknown.
int gltf_component_count(int type);
// Size in bytes of a component type (BYTE 1 ... FLOAT 4); 0 when unknown.
int gltf_component_size(int component_type);

// Reads accessor `index` as doubles: `out` is count by components (row per element), with
// byteStride, normalized integers (mapped to [0,1] / [-1,1]) and sparse substitution applied.
// An accessor without a bufferView reads as zeros (plus its sparse values).
Status read_gltf_accessor(const tinygltf::Model& model, int index, Eigen::MatrixXd* out);

// A skin's inverse bind matrices, one per joint (identity for a skin without them). False when the
// accessor is unreadable, not MAT4, or shorter than the joint list.
bool read_gltf_inverse_binds(const tinygltf::Model& model, const tinygltf::Skin& skin, Matrix4dList* out);

// A primitive's JOINTS_n / WEIGHTS_n, n = 0, 1, ... while both are present, side by side: #nv by
// 4 × sets (0 columns without JOINTS_0/WEIGHTS_0). Joint slots are read as doubles, unchecked.
// False when a set is unreadable or not #nv by 4.
bool read_gltf_skin_influences(const tinygltf::Model& model, const tinygltf::Primitive& prim, Eigen::Index nv,
                               Eigen::MatrixXd* joints, Eigen::MatrixXd* weights);

// TRIANGLES (4, or -1 = default), TRIANGLE_STRIP (5) and TRIANGLE_FAN (6) make triangles.
bool gltf_is_triangle_mode(int mode);

// The triangles of a triangle primitive: POSITION read and checked (VEC3; FLOAT, or with
// KHR_mesh_quantization also (normalized) BYTE/UNSIGNED_BYTE/SHORT/UNSIGNED_SHORT), indices
// unsigned-integer scalars in range, strips and fans unrolled into triangles (glTF 2.0 §3.7.2.1:
// strip p_i = {v_i, v_(i+1+i%2), v_(i+2−i%2)}, fan p_i = {v_(i+1), v_(i+2), v_0}). `label` prefixes
// every error ("mesh 0 ('body') primitive 1").
struct GltfTriangles {
  Eigen::MatrixXd P;  // #v by 3 POSITION (mesh space)
  Eigen::MatrixXi F;  // #f by 3 indices into P
};
Status read_gltf_triangles(const tinygltf::Model& model, const tinygltf::Primitive& prim, const std::string& label,
                           GltfTriangles* out);

}  // namespace mm::io
