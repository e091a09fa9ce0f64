// glTF for conversions and save_mesh (io-internal): a glTF asset flattened to one neutral
// mesh, and a minimal glTF written from a neutral mesh.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "io/asset.h"
#include "io/document.h"

namespace mm::io {

// All loaded primitives in world space (raw layout, V_raw_out positions), with NORMAL (world
// space; recomputed when asked), TEXCOORD_0 and COLOR_0 when every primitive has them.
ExportMesh gltf_export_mesh(const Asset& asset, const Eigen::MatrixXd& V_raw_out, bool recompute_normals);

// One scene, one node, one mesh, one primitive (TRIANGLES; POINTS when F is empty) with
// POSITION (+min/max), NORMAL, TEXCOORD_0, COLOR_0 as present, as .gltf (data URI) or .glb.
Status write_gltf_mesh(const ExportMesh& mesh, Format target, std::vector<uint8_t>* out);

}  // namespace mm::io
