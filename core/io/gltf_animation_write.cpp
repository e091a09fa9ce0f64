// The morph-target animation writer of io/gltf_animation.h.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "io/gltf_animation.h"
#include "io/gltf_builder.h"
#include "io/gltf_document.h"
#include "io/gltf_serialize.h"
#include "operators/operators.h"

namespace mm::io {

namespace gltf_anim_write_detail {

// Area-weighted vertex normals where vertices at identical rest positions (glTF seams) share
// their normal, so seams stay invisible while the morph plays (empty groups: +Y).
Eigen::MatrixXd seam_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::VectorXi& group,
                             int num_groups) {
  Eigen::MatrixXi G(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) G(f, k) = group[F(f, k)];
  const Eigen::MatrixXd acc = grouped_vertex_normals(V, F, G, num_groups);
  Eigen::MatrixXd N(V.rows(), 3);
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::RowVector3d n = acc.row(group[v]);
    N.row(v) = n.squaredNorm() > 0 ? n : Eigen::RowVector3d(0, 1, 0);
  }
  return N;
}

// Group of equal positions (exact), numbered in order of first appearance.
Eigen::VectorXi position_groups(const Eigen::MatrixXd& V, int* count) {
  std::map<std::tuple<double, double, double>, int> id;
  Eigen::VectorXi g(V.rows());
  for (int v = 0; v < V.rows(); ++v) {
    auto key = std::make_tuple(V(v, 0), V(v, 1), V(v, 2));
    auto it = id.find(key);
    if (it == id.end()) it = id.emplace(key, static_cast<int>(id.size())).first;
    g[v] = it->second;
  }
  *count = static_cast<int>(id.size());
  return g;
}

int append_scalar_accessor(tinygltf::Model* m, const std::vector<float>& v, bool min_max) {
  tinygltf::Accessor a;
  a.bufferView = gltf_append_view(m, 0, reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(float), 0);
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.count = v.size();
  a.type = TINYGLTF_TYPE_SCALAR;
  if (min_max && !v.empty()) {
    a.minValues = {*std::min_element(v.begin(), v.end())};
    a.maxValues = {*std::max_element(v.begin(), v.end())};
  }
  m->accessors.push_back(a);
  return static_cast<int>(m->accessors.size()) - 1;
}

// One morph target per frame on the meshes of `parts` (positions in world space, rows of each
// frame given by the parts' ranges), plus the weights animation.
struct SurfacePart {
  int node, mesh, primitive;
  int first, count;          // rows in the frames
  Eigen::Matrix4d world;     // node world transform the mesh will be drawn with
};

Status add_morph_animation(tinygltf::Model* m, const std::vector<SurfacePart>& parts, const Eigen::MatrixXi& F,
                           const Eigen::MatrixXd& V_rest, const std::vector<Eigen::MatrixXd>& frames,
                           const std::vector<double>& times, const MorphAnimationOptions& opt) {
  const int nframes = static_cast<int>(frames.size());
  if (m->buffers.empty()) m->buffers.emplace_back();
  int groups = 0;
  const Eigen::VectorXi group = position_groups(V_rest, &groups);
  const Eigen::MatrixXd N_rest = opt.normals ? seam_normals(V_rest, F, group, groups) : Eigen::MatrixXd();
  std::vector<Eigen::MatrixXd> N_frames;
  if (opt.normals)
    for (const Eigen::MatrixXd& X : frames) N_frames.push_back(seam_normals(X, F, group, groups));

  // Existing morph targets stay (their weights are held at 0); ours come after them.
  std::map<int, int> existing_targets;  // mesh → count before ours
  std::set<std::pair<int, int>> done;   // (mesh, primitive) written
  for (const SurfacePart& p : parts) {
    tinygltf::Mesh& mesh = m->meshes[p.mesh];
    if (!existing_targets.count(p.mesh)) {
      int before = 0;
      for (const auto& pr : mesh.primitives) before = std::max<int>(before, static_cast<int>(pr.targets.size()));
      existing_targets[p.mesh] = before;
    }
    if (done.count({p.mesh, p.primitive})) continue;  // mesh instanced twice: the first instance wins
    done.insert({p.mesh, p.primitive});
    tinygltf::Primitive& prim = mesh.primitives[p.primitive];
    const Eigen::Matrix4d inv = p.world.inverse();
    const Eigen::Matrix3d L_inv = inv.topLeftCorner<3, 3>();
    const Eigen::Matrix3d NL = p.world.topLeftCorner<3, 3>().transpose();  // world normal → local (then normalised)
    // Base positions in node space: the rest surface as it will be drawn without the skin.
    Eigen::MatrixXd base = (V_rest.middleRows(p.first, p.count) * L_inv.transpose()).rowwise() +
                           inv.topRightCorner<3, 1>().transpose();
    prim.attributes["POSITION"] = gltf_append_float_accessor(m, 0, base, true);
    prim.attributes.erase("JOINTS_0");
    prim.attributes.erase("WEIGHTS_0");
    prim.attributes.erase("JOINTS_1");
    prim.attributes.erase("WEIGHTS_1");
    Eigen::MatrixXd N_base;
    if (opt.normals) {
      N_base = N_rest.middleRows(p.first, p.count) * NL.transpose();
      N_base.rowwise().normalize();
      prim.attributes["NORMAL"] = gltf_append_float_accessor(m, 0, N_base, false);
    }
    while (static_cast<int>(prim.targets.size()) < existing_targets[p.mesh]) prim.targets.emplace_back();
    for (int f = 0; f < nframes; ++f) {
      const Eigen::MatrixXd d = (frames[f].middleRows(p.first, p.count) - V_rest.middleRows(p.first, p.count)) * L_inv.transpose();
      std::map<std::string, int> target;
      target["POSITION"] = gltf_append_float_accessor(m, 0, d, true);  // min/max required for POSITION
      if (opt.normals) {
        Eigen::MatrixXd n = N_frames[f].middleRows(p.first, p.count) * NL.transpose();
        n.rowwise().normalize();
        target["NORMAL"] = gltf_append_float_accessor(m, 0, n - N_base, false);
      }
      prim.targets.push_back(target);
    }
  }
  // Primitives of touched meshes that are not on the surface get zero targets (all primitives of
  // a mesh must have the same number of targets).
  for (const auto& [mi, before] : existing_targets) {
    tinygltf::Mesh& mesh = m->meshes[mi];
    const int total = before + nframes;
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      tinygltf::Primitive& prim = mesh.primitives[pi];
      if (static_cast<int>(prim.targets.size()) >= total) continue;
      auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end()) return Status::error(StatusCode::Unsupported, "primitive without POSITION");
      const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(m->accessors[pos->second].count, 3);
      const int acc = gltf_append_float_accessor(m, 0, zero, true);
      while (static_cast<int>(prim.targets.size()) < total) prim.targets.push_back({{"POSITION", acc}});
    }
    mesh.weights.assign(total, 0.0);
  }
  // Drop skins from surface nodes, and all existing animations (they move the skeleton).
  for (const SurfacePart& p : parts) m->nodes[p.node].skin = -1;
  m->animations.clear();
  tinygltf::Animation anim;
  anim.name = opt.animation_name;
  std::vector<float> t(times.begin(), times.end());
  const double t0 = times.empty() ? 0.0 : times.front();
  for (float& x : t) x = static_cast<float>(x - t0);
  const int input = append_scalar_accessor(m, t, true);
  std::map<int, int> sampler_of_mesh;
  std::set<int> nodes_done;
  for (const SurfacePart& p : parts) {
    if (nodes_done.count(p.node)) continue;
    nodes_done.insert(p.node);
    if (!sampler_of_mesh.count(p.mesh)) {
      const int total = existing_targets[p.mesh] + nframes;
      std::vector<float> w(static_cast<size_t>(nframes) * total, 0.0f);
      for (int f = 0; f < nframes; ++f) w[static_cast<size_t>(f) * total + existing_targets[p.mesh] + f] = 1.0f;
      tinygltf::AnimationSampler s;
      s.input = input;
      s.output = append_scalar_accessor(m, w, false);
      s.interpolation = "LINEAR";
      anim.samplers.push_back(s);
      sampler_of_mesh[p.mesh] = static_cast<int>(anim.samplers.size()) - 1;
    }
    tinygltf::AnimationChannel ch;
    ch.sampler = sampler_of_mesh[p.mesh];
    ch.target_node = p.node;
    ch.target_path = "weights";
    anim.channels.push_back(ch);
  }
  m->animations.push_back(anim);
  return Status::success();
}

// An accessor for animation sampler output (no bufferView target), VEC3 or VEC4 floats.
int append_vector_accessor(tinygltf::Model* m, const std::vector<float>& v, int components) {
  tinygltf::Accessor a;
  a.bufferView = gltf_append_view(m, 0, reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(float), 0);
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.count = v.size() / components;
  a.type = components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
  m->accessors.push_back(a);
  return static_cast<int>(m->accessors.size()) - 1;
}

// Translation and rotation channels of the prop-carrying joints, sampled at the frame times.
void add_node_tracks(tinygltf::Model* m, const std::vector<NodeTrack>& tracks, int input) {
  tinygltf::Animation& anim = m->animations.back();
  for (const NodeTrack& tr : tracks) {
    std::vector<float> t, r;
    for (size_t f = 0; f < tr.translation.size(); ++f) {
      for (int k = 0; k < 3; ++k) t.push_back(static_cast<float>(tr.translation[f][k]));
      const Eigen::Quaterniond& q = tr.rotation[f];
      for (double x : {q.x(), q.y(), q.z(), q.w()}) r.push_back(static_cast<float>(x));
    }
    for (const auto& [path, values, comps] : {std::make_tuple("translation", &t, 3), std::make_tuple("rotation", &r, 4)}) {
      tinygltf::AnimationSampler smp;
      smp.input = input;
      smp.output = append_vector_accessor(m, *values, comps);
      smp.interpolation = "LINEAR";
      anim.samplers.push_back(smp);
      tinygltf::AnimationChannel ch;
      ch.sampler = static_cast<int>(anim.samplers.size()) - 1;
      ch.target_node = tr.node;
      ch.target_path = path;
      anim.channels.push_back(ch);
    }
  }
}

}  // namespace gltf_anim_write_detail

Status write_morph_animation(const Asset& target, const AnimatedCharacter* tc, const std::vector<Eigen::MatrixXd>& frames,
                             const std::vector<double>& times, std::vector<uint8_t>* glb, const MorphAnimationOptions& opt,
                             const std::vector<NodeTrack>& tracks) {
  using namespace gltf_anim_write_detail;
  if (frames.empty() || frames.size() != times.size())
    return Status::error(StatusCode::InvalidArgument, "morph animation needs one time per frame (and at least one frame)");
  for (size_t k = 1; k < times.size(); ++k)
    if (!(times[k] > times[k - 1])) return Status::error(StatusCode::InvalidArgument, "frame times must increase");
  const tinygltf::Model* src = gltf_model(target);
  tinygltf::Model m;
  std::vector<SurfacePart> parts;
  Eigen::MatrixXd V_rest;
  Eigen::MatrixXi F;
  std::vector<std::vector<uint8_t>> image_files;
  if (src) {
    if (!tc) return Status::error(StatusCode::InvalidArgument, "glTF target without its character description");
    m = *src;
    image_files = static_cast<const GltfDocument&>(*target.document).image_files;
    const Matrix4dList world = node_world_matrices(*tc, -1, 0);
    for (const CharacterPart& p : tc->parts) parts.push_back({p.node, p.mesh, p.primitive, p.first_vertex, p.num_vertices, world[p.node]});
    V_rest = tc->V_rest;
    F = tc->F;
  } else {
    V_rest = target.V_raw;
    F = target.F_raw;
    m.asset.version = "2.0";
    m.asset.generator = "MeshMorph retarget";
    m.buffers.emplace_back();
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.indices = gltf_append_index_accessor(&m, 0, F);
    prim.attributes["POSITION"] = gltf_append_float_accessor(&m, 0, V_rest, true);
    // A plain dielectric material: without one, viewers apply glTF's default (metallic 1),
    // which renders black in three.js unless the scene has an environment map.
    tinygltf::Material material;
    material.name = "target";
    material.pbrMetallicRoughness.metallicFactor = 0.0;
    material.pbrMetallicRoughness.roughnessFactor = 0.8;
    material.pbrMetallicRoughness.baseColorFactor = {0.8, 0.8, 0.8, 1.0};
    m.materials.push_back(material);
    prim.material = 0;
    tinygltf::Mesh mesh;
    mesh.name = "target";
    mesh.primitives.push_back(prim);
    m.meshes.push_back(mesh);
    tinygltf::Node node;
    node.mesh = 0;
    node.name = "target";
    m.nodes.push_back(node);
    tinygltf::Scene scene;
    scene.nodes = {0};
    m.scenes.push_back(scene);
    m.defaultScene = 0;
    parts.push_back({0, 0, 0, 0, static_cast<int>(V_rest.rows()), Eigen::Matrix4d::Identity()});
  }
  for (const Eigen::MatrixXd& X : frames)
    if (X.rows() != V_rest.rows() || X.cols() != 3 || !X.allFinite())
      return Status::error(StatusCode::InvalidArgument, "every frame must have " + std::to_string(V_rest.rows()) +
                                                            " finite positions (the target surface)");
  Status s = add_morph_animation(&m, parts, F, V_rest, frames, times, opt);
  if (!s.ok()) return s;
  if (src && !tracks.empty()) {
    for (const NodeTrack& t : tracks)
      if (t.node < 0 || t.node >= static_cast<int>(m.nodes.size()) || t.translation.size() != frames.size() ||
          t.rotation.size() != frames.size())
        return Status::error(StatusCode::InvalidArgument, "prop track of node " + std::to_string(t.node) +
                                                              " does not match the target or the frame count");
    const tinygltf::Animation& anim = m.animations.back();
    if (!anim.samplers.empty()) add_node_tracks(&m, tracks, anim.samplers.front().input);
  }
  GltfFiles files;
  s = serialize_gltf(std::move(m), image_files, Format::Glb, "", &files);
  if (!s.ok()) return s;
  *glb = std::move(files.main);
  return Status::success();
}

}  // namespace mm::io
