#include "io/debug_lines_glb.h"

#include "io/gltf_builder.h"
#include "io/gltf_document.h"

namespace mm::io {

Status debug_geometry_glb(const std::vector<DebugGeometry>& sets, std::vector<uint8_t>* bytes) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "meshmorph";
  model.buffers.emplace_back();
  tinygltf::Scene scene;
  for (const DebugGeometry& g : sets) {
    if (g.P.rows() == 0) continue;
    if (!g.P.allFinite()) return Status::error(StatusCode::InvalidArgument, "debug geometry '" + g.name + "' is not finite");
    const int n = static_cast<int>(g.P.rows());
    Eigen::MatrixXi I;
    int mode = TINYGLTF_MODE_POINTS;
    if (!g.lines.empty()) {
      mode = TINYGLTF_MODE_LINE;
      I.resize(static_cast<int>(g.lines.size()), 2);
      for (size_t i = 0; i < g.lines.size(); ++i) I.row(static_cast<int>(i)) << g.lines[i].first, g.lines[i].second;
    } else if (g.F.rows() > 0) {
      mode = TINYGLTF_MODE_TRIANGLES;
      I = g.F;
    }
    if (I.size() > 0 && (I.minCoeff() < 0 || I.maxCoeff() >= n))
      return Status::error(StatusCode::InvalidArgument, "debug geometry '" + g.name + "' has indices out of range");
    tinygltf::Primitive prim;
    prim.mode = mode;
    prim.attributes["POSITION"] = gltf_append_float_accessor(&model, 0, g.P, true);
    if (I.size() > 0) {
      prim.indices = gltf_append_index_accessor(&model, 0, I);
    }
    tinygltf::Material mat;
    mat.name = g.name;
    mat.pbrMetallicRoughness.baseColorFactor = {g.color[0], g.color[1], g.color[2], g.color[3]};
    mat.pbrMetallicRoughness.metallicFactor = 0;
    mat.pbrMetallicRoughness.roughnessFactor = 1;
    mat.doubleSided = true;
    if (g.color[3] < 1) mat.alphaMode = "BLEND";
    prim.material = static_cast<int>(model.materials.size());
    model.materials.push_back(mat);
    tinygltf::Mesh mesh;
    mesh.name = g.name;
    mesh.primitives.push_back(prim);
    tinygltf::Node node;
    node.name = g.name;
    node.mesh = static_cast<int>(model.meshes.size());
    model.meshes.push_back(mesh);
    scene.nodes.push_back(static_cast<int>(model.nodes.size()));
    model.nodes.push_back(node);
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  return save_gltf_model_to_memory(model, Format::Glb, bytes);
}

}  // namespace mm::io
