// Bounds-checked reading of glTF accessors (io-internal): every offset, stride and sparse
// index is checked against the buffer it points into, so a malformed file gives ParseError.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
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

}  // namespace mm::io
