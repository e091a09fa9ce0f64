// Appending data to a tinygltf::Model (io-internal): new bufferViews and accessors at the end
// of a buffer, with the alignment and min/max the glTF validator requires.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "io/gltf_document.h"

namespace mm::io {

// Appends `size` bytes to buffer `buffer` (4-byte aligned start, zero padding) as a new
// bufferView with `target` (0: none); returns the bufferView index.
int gltf_append_view(tinygltf::Model* model, int buffer, const uint8_t* data, size_t size, int target);

// Appends a FLOAT accessor of type VEC2/VEC3 (columns of M, cast to float) in a new bufferView
// (ARRAY_BUFFER) of `buffer`; with_min_max writes min/max of the float values. Returns its index.
int gltf_append_float_accessor(tinygltf::Model* model, int buffer, const Eigen::MatrixXd& M, bool with_min_max);

// Appends a SHORT (non-normalized) VEC3 accessor of the rows of Q, which must hold integers in
// [-32767, 32767], in a new bufferView (ARRAY_BUFFER) with byteStride 8 (vertex attributes are
// 4-byte aligned); with min/max. For KHR_mesh_quantization (the caller declares the extension).
int gltf_append_short_vec3_accessor(tinygltf::Model* model, int buffer, const Eigen::MatrixXd& Q);

// Appends an UNSIGNED_INT SCALAR index accessor (ELEMENT_ARRAY_BUFFER) for the rows of F, row by
// row (triangles: 3 columns; line segments: 2).
int gltf_append_index_accessor(tinygltf::Model* model, int buffer, const Eigen::MatrixXi& F);

}  // namespace mm::io
