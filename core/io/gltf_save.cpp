#include "io/gltf_save.h"

#include <cmath>
#include <algorithm>
#include <map>
#include <set>

#include <Eigen/LU>

#include "io/gltf_accessor.h"
#include "io/gltf_builder.h"
#include "io/gltf_document.h"
#include "operators/operators.h"
#include "mesh/mesh.h"

namespace mm::io {

namespace detail {

// One node's use of a mesh: new local positions of each of its loaded primitives.
struct GltfInstance {
  int node = -1;
  bool changed = false;
  std::map<int, Eigen::MatrixXd> local;  // primitive index -> #n by 3 local positions
  std::map<int, Eigen::MatrixXi> faces;  // primitive index -> triangles over local vertices
};

static bool gltf_same_positions(const GltfInstance& a, const GltfInstance& b) {
  for (const auto& [p, A] : a.local) {
    const auto it = b.local.find(p);
    if (it == b.local.end() || it->second.rows() != A.rows()) return false;
    // Float storage and inverse transforms leave ~1e-7 relative noise between instances that
    // are meant to be identical.
    const double tol = 1e-6 * std::max(bounding_box_diagonal(A), 1e-30);
    if (A.rows() > 0 && (A - it->second).cwiseAbs().maxCoeff() > tol) return false;
  }
  return true;
}

// Writes an instance's positions (and normals) into mesh `mesh_index` as new accessors.
static Status gltf_write_instance(tinygltf::Model* m, int mesh_index, const GltfInstance& inst,
                                  const SaveOptions& opt) {
  for (const auto& [pi, L] : inst.local) {
    tinygltf::Primitive& prim = m->meshes[mesh_index].primitives[pi];
    prim.attributes["POSITION"] = gltf_append_float_accessor(m, 0, L, true);
    const auto n_it = prim.attributes.find("NORMAL");
    if (!opt.recompute_normals || n_it == prim.attributes.end()) continue;
    const Eigen::MatrixXi& F = inst.faces.at(pi);
    Eigen::MatrixXd N = grouped_vertex_normals(L, F, F, static_cast<int>(L.rows()));
    Eigen::MatrixXd N_old;
    const bool have_old = read_gltf_accessor(*m, n_it->second, &N_old).ok() && N_old.rows() == L.rows() &&
                          N_old.cols() == 3;
    // Vertices no triangle uses keep their old normal: NORMAL must be unit length everywhere.
    for (Eigen::Index r = 0; r < N.rows(); ++r) {
      if (N.row(r).squaredNorm() > 0) continue;
      if (have_old && std::abs(N_old.row(r).norm() - 1.0) < 1e-3) N.row(r) = N_old.row(r).normalized();
      else N.row(r) << 0, 0, 1;
    }
    prim.attributes["NORMAL"] = gltf_append_float_accessor(m, 0, N, false);
  }
  return Status::success();
}

// The validator's rule (ACCESSOR_WEIGHTS_NON_NORMALIZED): per vertex, the float32 sum of
// the weights must be within 2e-7 per non-zero weight of 1. True when `W` breaks it anywhere.
static bool gltf_weights_need_repair(const Eigen::MatrixXd& W) {
  for (Eigen::Index r = 0; r < W.rows(); ++r) {
    float sum = 0;
    double tol = 0;
    for (Eigen::Index c = 0; c < W.cols(); ++c)
      if (W(r, c) != 0) {
        sum += static_cast<float>(W(r, c));
        tol += 2e-7;
      }
    if (std::abs(static_cast<double>(sum) - 1.0) > tol) return true;
  }
  return false;
}

// Exporters often write weights whose sums drift from 1 (RobotExpressive: up to 1.09), which
// the glTF validator reports as errors. Every GLB we write must validate, so such WEIGHTS_0
// accessors are replaced by normalized FLOAT copies; files with valid weights are untouched.
// A vertex with all-zero weights gets weight 1 on its first joint slot.
static void gltf_repair_weights(tinygltf::Model* m) {
  std::map<int, int> repaired;  // old accessor -> new accessor (accessors may be shared)
  for (tinygltf::Mesh& mesh : m->meshes)
    for (tinygltf::Primitive& prim : mesh.primitives) {
      // Several weight sets would have to be normalized together; they are rare, leave them.
      if (prim.attributes.count("WEIGHTS_1")) continue;
      const auto it = prim.attributes.find("WEIGHTS_0");
      if (it == prim.attributes.end()) continue;
      const auto done = repaired.find(it->second);
      if (done != repaired.end()) {
        it->second = done->second;
        continue;
      }
      Eigen::MatrixXd W;
      if (!read_gltf_accessor(*m, it->second, &W).ok() || W.cols() != 4 || !gltf_weights_need_repair(W)) continue;
      for (Eigen::Index r = 0; r < W.rows(); ++r) {
        W.row(r) = W.row(r).cwiseMax(0.0);
        const double sum = W.row(r).sum();
        if (sum > 0) W.row(r) /= sum;
        else W.row(r) << 1, 0, 0, 0;
      }
      const int fresh = gltf_append_float_accessor(m, 0, W, false);
      repaired[it->second] = fresh;
      it->second = fresh;
    }
}

}  // namespace detail

Status save_gltf_document(const Asset& asset, const Eigen::MatrixXd& V_raw_out, const std::vector<char>& moved,
                          Format target, const SaveOptions& opt, const std::string& sidecar_stem, GltfFiles* out) {
  using namespace detail;
  const auto& doc = static_cast<const GltfDocument&>(*asset.document);
  tinygltf::Model m = doc.model;
  if (m.buffers.empty()) m.buffers.emplace_back();

  // Group the loaded primitives by mesh, then by node, in scene order.
  std::map<int, std::vector<GltfInstance>> by_mesh;
  for (const PrimitiveRef& ref : asset.primitives) {
    std::vector<GltfInstance>& list = by_mesh[ref.mesh];
    if (list.empty() || list.back().node != ref.node) {
      list.emplace_back();
      list.back().node = ref.node;
    }
    GltfInstance& inst = list.back();
    const int pos_accessor = doc.model.meshes[ref.mesh].primitives[ref.primitive].attributes.at("POSITION");
    Eigen::MatrixXd L;
    Status s = read_gltf_accessor(doc.model, pos_accessor, &L);
    if (!s.ok()) return s;
    const Eigen::Matrix4d inv = ref.world.inverse();
    for (int v = 0; v < ref.num_vertices; ++v) {
      if (!moved[ref.first_vertex + v]) continue;
      const Eigen::Vector3d x = V_raw_out.row(ref.first_vertex + v).transpose();
      if (ref.rest_skin.rows() == ref.num_vertices) {
        // Through the vertex's rest-pose skin map (asset.h): skinned at rest it lands on x.
        const Eigen::Matrix<double, 3, 4> a = rest_skin_map(ref.rest_skin, v);
        L.row(v) = a.leftCols<3>().partialPivLu().solve(x - a.col(3)).transpose();
      } else {
        const Eigen::Vector4d p = inv * x.homogeneous();
        L.row(v) << p.x(), p.y(), p.z();
      }
      inst.changed = true;
    }
    if (!L.allFinite())
      return Status::error(StatusCode::NumericalError, "node " + std::to_string(ref.node) +
                                                           " has a singular transform; cannot map positions back");
    inst.local[ref.primitive] = L;
    inst.faces[ref.primitive] =
        asset.F_raw.middleRows(ref.first_face, ref.num_faces).array() - ref.first_vertex;
  }

  const tinygltf::Model& original = doc.model;
  for (auto& [mesh_index, instances] : by_mesh) {
    bool any = false;
    for (const GltfInstance& inst : instances) any = any || inst.changed;
    if (!any) continue;
    const GltfInstance& owner = instances[0];
    if (owner.changed) {
      Status s = gltf_write_instance(&m, mesh_index, owner, opt);
      if (!s.ok()) return s;
    }
    std::vector<std::pair<int, const GltfInstance*>> copies;  // mesh index, content
    for (size_t k = 1; k < instances.size(); ++k) {
      const GltfInstance& inst = instances[k];
      if (gltf_same_positions(inst, owner)) continue;
      int target_mesh = -1;
      for (const auto& [ci, content] : copies)
        if (gltf_same_positions(inst, *content)) target_mesh = ci;
      if (target_mesh < 0) {
        // The copy starts from the original mesh: an unchanged instance keeps the original
        // accessors; a changed one gets its own.
        m.meshes.push_back(original.meshes[mesh_index]);
        target_mesh = static_cast<int>(m.meshes.size()) - 1;
        if (!m.meshes[target_mesh].name.empty()) m.meshes[target_mesh].name += "_node" + std::to_string(inst.node);
        if (inst.changed) {
          Status s = gltf_write_instance(&m, target_mesh, inst, opt);
          if (!s.ok()) return s;
        }
        copies.emplace_back(target_mesh, &inst);
      }
      m.nodes[inst.node].mesh = target_mesh;
    }
  }
  if (opt.repair_weights) gltf_repair_weights(&m);
  return serialize_gltf(std::move(m), doc.image_files, target, sidecar_stem, out);
}

}  // namespace mm::io

namespace mm::io {

Status save_gltf_with_mesh(const Asset& asset, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, Format target,
                           const std::string& sidecar_stem, GltfFiles* out) {
  const auto& doc = static_cast<const GltfDocument&>(*asset.document);
  tinygltf::Model m = doc.model;
  if (m.buffers.empty()) m.buffers.emplace_back();
  // The loaded primitives stop being drawn: removed from their mesh, or the mesh (and its skin
  // and morph-weight animation channels) detached from its nodes when nothing else is left.
  std::map<int, std::set<int>> loaded;  // mesh → loaded primitive indices
  for (const PrimitiveRef& ref : asset.primitives) loaded[ref.mesh].insert(ref.primitive);
  std::set<int> detached_nodes;
  for (const auto& [mesh, prims] : loaded) {
    tinygltf::Mesh& mesh_ref = m.meshes[mesh];
    if (prims.size() < mesh_ref.primitives.size()) {
      std::vector<tinygltf::Primitive> rest;
      for (size_t p = 0; p < mesh_ref.primitives.size(); ++p)
        if (!prims.count(static_cast<int>(p))) rest.push_back(mesh_ref.primitives[p]);
      mesh_ref.primitives = rest;
      mesh_ref.weights.clear();
      continue;
    }
    for (size_t n = 0; n < m.nodes.size(); ++n)
      if (m.nodes[n].mesh == mesh) {
        m.nodes[n].mesh = -1;
        m.nodes[n].skin = -1;
        m.nodes[n].weights.clear();
        detached_nodes.insert(static_cast<int>(n));
      }
  }
  for (auto& anim : m.animations)
    anim.channels.erase(std::remove_if(anim.channels.begin(), anim.channels.end(),
                                       [&](const tinygltf::AnimationChannel& c) {
                                         return c.target_path == "weights" && detached_nodes.count(c.target_node);
                                       }),
                        anim.channels.end());
  m.animations.erase(std::remove_if(m.animations.begin(), m.animations.end(),
                                    [](const tinygltf::Animation& a) { return a.channels.empty(); }),
                     m.animations.end());
  // The new geometry: one primitive with the first loaded primitive's material, at the root.
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.attributes["POSITION"] = gltf_append_float_accessor(&m, 0, V, true);
  prim.attributes["NORMAL"] = gltf_append_float_accessor(&m, 0, vertex_normals(V, F), false);
  prim.indices = gltf_append_index_accessor(&m, 0, F);
  if (!asset.primitives.empty()) {
    const PrimitiveRef& first = asset.primitives[0];
    prim.material = doc.model.meshes[first.mesh].primitives[first.primitive].material;
  }
  tinygltf::Mesh mesh;
  mesh.name = "merged";
  mesh.primitives.push_back(prim);
  m.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = "merged";
  node.mesh = static_cast<int>(m.meshes.size()) - 1;
  m.nodes.push_back(node);
  if (m.scenes.empty()) m.scenes.emplace_back();
  const int scene = m.defaultScene >= 0 && m.defaultScene < static_cast<int>(m.scenes.size()) ? m.defaultScene : 0;
  m.scenes[scene].nodes.push_back(static_cast<int>(m.nodes.size()) - 1);
  return serialize_gltf(std::move(m), doc.image_files, target, sidecar_stem, out);
}

}  // namespace mm::io
