#include "io/gltf_export.h"

#include <cmath>

#include <Eigen/LU>

#include "io/gltf_accessor.h"
#include "io/gltf_builder.h"
#include "io/gltf_document.h"
#include "io/gltf_serialize.h"
#include "operators/operators.h"

namespace mm::io {

ExportMesh gltf_export_mesh(const Asset& asset, const Eigen::MatrixXd& V_raw_out, bool recompute_normals) {
  ExportMesh out;
  out.V = V_raw_out;
  out.F = asset.F_raw;
  const tinygltf::Model* m = gltf_model(asset);
  if (!m) return out;
  const Eigen::Index n = V_raw_out.rows();
  // An attribute is exported only when every primitive has it (a partial attribute has no
  // meaning in a single-mesh format).
  auto gather = [&](const char* name, int cols, Eigen::MatrixXd* dst, bool normals) {
    dst->resize(n, cols);
    for (const PrimitiveRef& ref : asset.primitives) {
      const tinygltf::Primitive& prim = m->meshes[ref.mesh].primitives[ref.primitive];
      const auto it = prim.attributes.find(name);
      Eigen::MatrixXd A;
      if (it == prim.attributes.end() || !read_gltf_accessor(*m, it->second, &A).ok() || A.rows() != ref.num_vertices ||
          A.cols() < cols) {
        dst->resize(0, 0);
        return;
      }
      if (normals) {
        // Normals transform with the inverse transpose of the node's linear part.
        const Eigen::Matrix3d Nm = ref.world.topLeftCorner<3, 3>().inverse().transpose();
        const bool rest = ref.rest_skin.rows() == ref.num_vertices;  // per-vertex maps (asset.h)
        for (int v = 0; v < ref.num_vertices; ++v) {
          const Eigen::Matrix3d N = rest ? Eigen::Matrix3d(rest_skin_map(ref.rest_skin, v).leftCols<3>().inverse().transpose()) : Nm;
          dst->row(ref.first_vertex + v) = (N * A.row(v).leftCols<3>().transpose()).normalized().transpose();
        }
      } else {
        dst->middleRows(ref.first_vertex, ref.num_vertices) = A.leftCols(cols);
      }
    }
  };
  gather("NORMAL", 3, &out.N, true);
  gather("TEXCOORD_0", 2, &out.UV, false);
  gather("COLOR_0", 3, &out.C, false);
  if (out.N.rows() == n && recompute_normals) {
    const Eigen::MatrixXd R = grouped_vertex_normals(V_raw_out, asset.F_raw, asset.F_raw, static_cast<int>(n));
    for (Eigen::Index r = 0; r < n; ++r)
      if (R.row(r).squaredNorm() > 0) out.N.row(r) = R.row(r);
  }
  return out;
}

Status write_gltf_mesh(const ExportMesh& mesh, Format target, std::vector<uint8_t>* out) {
  if (mesh.V.rows() == 0) return Status::error(StatusCode::InvalidArgument, "cannot write a glTF without vertices");
  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = "MeshMorph";
  m.buffers.emplace_back();
  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = gltf_append_float_accessor(&m, 0, mesh.V, true);
  const Eigen::Index n = mesh.V.rows();
  if (mesh.N.rows() == n && mesh.N.cols() == 3) {
    Eigen::MatrixXd N = mesh.N;
    // NORMAL must be unit length for the validator; zero rows (isolated vertices) get +z.
    for (Eigen::Index r = 0; r < n; ++r) {
      const double len = N.row(r).norm();
      if (len > 0 && std::isfinite(len)) N.row(r) /= len;
      else N.row(r) << 0, 0, 1;
    }
    prim.attributes["NORMAL"] = gltf_append_float_accessor(&m, 0, N, false);
  }
  if (mesh.UV.rows() == n && mesh.UV.cols() == 2)
    prim.attributes["TEXCOORD_0"] = gltf_append_float_accessor(&m, 0, mesh.UV, false);
  if (mesh.C.rows() == n && mesh.C.cols() == 3)
    prim.attributes["COLOR_0"] = gltf_append_float_accessor(&m, 0, mesh.C.cwiseMax(0.0).cwiseMin(1.0), false);
  if (mesh.F.rows() > 0) {
    prim.indices = gltf_append_index_accessor(&m, 0, mesh.F);
    prim.mode = TINYGLTF_MODE_TRIANGLES;
  } else {
    prim.mode = TINYGLTF_MODE_POINTS;
  }
  tinygltf::Mesh gm;
  gm.name = "mesh";
  gm.primitives.push_back(prim);
  m.meshes.push_back(gm);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "mesh";
  m.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  m.scenes.push_back(scene);
  m.defaultScene = 0;
  GltfFiles files;
  Status s = serialize_gltf(std::move(m), {}, target, "", &files);
  if (s.ok()) *out = std::move(files.main);
  return s;
}

}  // namespace mm::io
