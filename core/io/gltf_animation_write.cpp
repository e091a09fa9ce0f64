// The morph-target animation writer of io/gltf_animation.h.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "io/gltf_animation.h"
#include "io/gltf_builder.h"
#include "io/gltf_document.h"
#include "io/gltf_serialize.h"
#include "character/morph_basis.h"
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

// The surface primitives the morph targets go on: positions in world space, rows of each frame
// given by the parts' ranges.
struct SurfacePart {
  int node, mesh, primitive;
  int first, count;          // rows in the frames
  Eigen::Matrix4d world;     // node world transform the mesh will be drawn with
};

// A surface primitive as written: its part and the map from world to node space.
struct WrittenPart {
  const SurfacePart* part;
  Eigen::Matrix3d L_inv;     // world → node, linear part (displacements)
  Eigen::Vector3d t_inv;     // world → node, translation
  Eigen::Matrix3d NL;        // world normal → node normal (normalise after)
  Eigen::MatrixXd base;      // count by 3 POSITION written (node space)
  Eigen::MatrixXd N_base;    // count by 3 NORMAL written (node space; empty without normals)
};

// Morph targets of the surface: the written primitives and how many targets each mesh had before.
struct SurfaceMorphs {
  std::vector<WrittenPart> written;
  std::map<int, int> existing_targets;  // mesh → count before ours (their weights are held at 0)
};

Eigen::MatrixXd node_normals(const Eigen::MatrixXd& N_world, const WrittenPart& w) {
  Eigen::MatrixXd n = N_world.middleRows(w.part->first, w.part->count) * w.NL.transpose();
  n.rowwise().normalize();
  return n;
}

// Base POSITION (the rest surface as drawn without the skin) and NORMAL of every surface
// primitive, skins dropped; existing morph targets stay first.
SurfaceMorphs surface_morphs(tinygltf::Model* m, const std::vector<SurfacePart>& parts, const Eigen::MatrixXd& V_rest,
                             const Eigen::MatrixXd& N_rest) {
  SurfaceMorphs s;
  std::set<std::pair<int, int>> done;  // (mesh, primitive) written
  for (const SurfacePart& p : parts) {
    tinygltf::Mesh& mesh = m->meshes[p.mesh];
    if (!s.existing_targets.count(p.mesh)) {
      int before = 0;
      for (const auto& pr : mesh.primitives) before = std::max<int>(before, static_cast<int>(pr.targets.size()));
      s.existing_targets[p.mesh] = before;
    }
    if (done.count({p.mesh, p.primitive})) continue;  // mesh instanced twice: the first instance wins
    done.insert({p.mesh, p.primitive});
    WrittenPart w;
    w.part = &p;
    const Eigen::Matrix4d inv = p.world.inverse();
    w.L_inv = inv.topLeftCorner<3, 3>();
    w.t_inv = inv.topRightCorner<3, 1>();
    w.NL = p.world.topLeftCorner<3, 3>().transpose();
    w.base = (V_rest.middleRows(p.first, p.count) * w.L_inv.transpose()).rowwise() + w.t_inv.transpose();
    tinygltf::Primitive& prim = mesh.primitives[p.primitive];
    prim.attributes["POSITION"] = gltf_append_float_accessor(m, 0, w.base, true);
    for (const char* a : {"JOINTS_0", "WEIGHTS_0", "JOINTS_1", "WEIGHTS_1"}) prim.attributes.erase(a);
    if (N_rest.size()) {
      w.N_base = node_normals(N_rest, w);
      prim.attributes["NORMAL"] = gltf_append_float_accessor(m, 0, w.N_base, false);
    }
    while (static_cast<int>(prim.targets.size()) < s.existing_targets[p.mesh]) prim.targets.emplace_back();
    s.written.push_back(std::move(w));
  }
  return s;
}

// Primitives of touched meshes that are not on the surface get zero targets (all primitives of
// a mesh must have the same number of targets); mesh.weights all 0.
Status pad_other_primitives(tinygltf::Model* m, const SurfaceMorphs& s, int ours) {
  for (const auto& [mi, before] : s.existing_targets) {
    tinygltf::Mesh& mesh = m->meshes[mi];
    const int total = before + ours;
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
  return Status::success();
}

// The animation (replacing all existing ones: they move the skeleton) with one weights channel
// per surface node. W: #frames by `ours` weights of our targets (float, as stored).
void add_weights_animation(tinygltf::Model* m, const std::vector<SurfacePart>& parts, const SurfaceMorphs& s,
                           const Eigen::MatrixXf& W, const std::vector<double>& times, const std::string& name) {
  for (const SurfacePart& p : parts) m->nodes[p.node].skin = -1;
  m->animations.clear();
  tinygltf::Animation anim;
  anim.name = name;
  std::vector<float> t(times.begin(), times.end());
  const double t0 = times.empty() ? 0.0 : times.front();
  for (float& x : t) x = static_cast<float>(x - t0);
  const int input = append_scalar_accessor(m, t, true);
  const int nframes = static_cast<int>(W.rows()), ours = static_cast<int>(W.cols());
  std::map<int, int> sampler_of_mesh;
  std::set<int> nodes_done;
  for (const SurfacePart& p : parts) {
    if (nodes_done.count(p.node)) continue;
    nodes_done.insert(p.node);
    if (!sampler_of_mesh.count(p.mesh)) {
      const int before = s.existing_targets.at(p.mesh), total = before + ours;
      std::vector<float> w(static_cast<size_t>(nframes) * total, 0.0f);
      for (int f = 0; f < nframes; ++f)
        for (int k = 0; k < ours; ++k) w[static_cast<size_t>(f) * total + before + k] = W(f, k);
      tinygltf::AnimationSampler smp;
      smp.input = input;
      smp.output = append_scalar_accessor(m, w, false);
      smp.interpolation = "LINEAR";
      anim.samplers.push_back(smp);
      sampler_of_mesh[p.mesh] = static_cast<int>(anim.samplers.size()) - 1;
    }
    tinygltf::AnimationChannel ch;
    ch.sampler = sampler_of_mesh[p.mesh];
    ch.target_node = p.node;
    ch.target_path = "weights";
    anim.channels.push_back(ch);
  }
  m->animations.push_back(anim);
}

// Frames layout: one morph target per frame.
Status add_frame_morphs(tinygltf::Model* m, const std::vector<SurfacePart>& parts, const Eigen::MatrixXi& F,
                        const Eigen::MatrixXd& V_rest, const std::vector<Eigen::MatrixXd>& frames,
                        const std::vector<double>& times, const MorphAnimationOptions& opt, MorphAnimationReport* report) {
  const int nframes = static_cast<int>(frames.size());
  if (m->buffers.empty()) m->buffers.emplace_back();
  int groups = 0;
  const Eigen::VectorXi group = position_groups(V_rest, &groups);
  const Eigen::MatrixXd N_rest = opt.normals ? seam_normals(V_rest, F, group, groups) : Eigen::MatrixXd();
  std::vector<Eigen::MatrixXd> N_frames;
  if (opt.normals)
    for (const Eigen::MatrixXd& X : frames) N_frames.push_back(seam_normals(X, F, group, groups));
  const SurfaceMorphs s = surface_morphs(m, parts, V_rest, N_rest);
  for (const WrittenPart& w : s.written) {
    tinygltf::Primitive& prim = m->meshes[w.part->mesh].primitives[w.part->primitive];
    for (int f = 0; f < nframes; ++f) {
      const Eigen::MatrixXd d =
          (frames[f].middleRows(w.part->first, w.part->count) - V_rest.middleRows(w.part->first, w.part->count)) * w.L_inv.transpose();
      std::map<std::string, int> target;
      target["POSITION"] = gltf_append_float_accessor(m, 0, d, true);  // min/max required for POSITION
      if (opt.normals) {
        const Eigen::MatrixXd n = node_normals(N_frames[f], w);
        target["NORMAL"] = gltf_append_float_accessor(m, 0, n - w.N_base, false);
      }
      prim.targets.push_back(target);
    }
  }
  if (Status st = pad_other_primitives(m, s, nframes); !st.ok()) return st;
  add_weights_animation(m, parts, s, Eigen::MatrixXf::Identity(nframes, nframes), times, opt.animation_name);
  report->compact = false;
  report->targets = nframes;
  return Status::success();
}

// Compact layout (see gltf_animation.h): the basis in each part's node space, as stored.
struct CompactPart {
  Eigen::MatrixXd mean;      // count by 3 mean displacement (float-rounded)
  Eigen::MatrixXd Q;         // 3·count by K stored component values (integers when quantized)
  Eigen::MatrixXd N_mean;    // count by 3 mean NORMAL delta
  Eigen::MatrixXd N_Q;       // 3·count by K_N NORMAL deltas per unit of stored weight (first K_N components)
};

double float_rounded(double x) { return static_cast<double>(static_cast<float>(x)); }

// Rows 3v..3v+2 of U (3·#V by K) for the part's vertices, turned into node space.
Eigen::MatrixXd node_components(const Eigen::MatrixXd& U, const WrittenPart& w, int K) {
  Eigen::MatrixXd out(3 * w.part->count, K);
  for (int v = 0; v < w.part->count; ++v)
    out.middleRows(3 * v, 3) = w.L_inv * U.block(3 * (w.part->first + v), 0, 3, K);
  return out;
}

// Per-component storage scale δ_k: max |coordinate| over all parts / 32767 (quantized), else 1.
Eigen::VectorXd component_scales(const std::vector<Eigen::MatrixXd>& U_parts, int K, bool quantize) {
  Eigen::VectorXd delta = Eigen::VectorXd::Ones(K);
  if (!quantize) return delta;
  for (int k = 0; k < K; ++k) {
    double big = 0;
    for (const Eigen::MatrixXd& U : U_parts) big = std::max(big, U.col(k).cwiseAbs().maxCoeff());
    delta[k] = big > 0 ? big / 32767.0 : 1.0;
  }
  return delta;
}

// Max distance (world) between the frames and what a viewer decodes: base + mean + Σ c_fk q_k,
// through the node transform, with every stored value as stored. Frames in blocks of 32.
double compact_error(const std::vector<WrittenPart>& written, const std::vector<CompactPart>& data,
                     const std::vector<Eigen::MatrixXd>& frames, const Eigen::MatrixXf& C) {
  double worst2 = 0;
  const int nframes = static_cast<int>(frames.size()), K = static_cast<int>(C.cols()) - 1;
  const Eigen::MatrixXd Cd = C.rightCols(K).cast<double>();
  for (size_t i = 0; i < written.size(); ++i) {
    const WrittenPart& w = written[i];
    const Eigen::Matrix3d L = w.part->world.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = w.part->world.topRightCorner<3, 1>();
    const Eigen::MatrixXd rest = w.base.unaryExpr(&float_rounded) + data[i].mean;
    for (int f0 = 0; f0 < nframes; f0 += 32) {
      const int b = std::min(32, nframes - f0);
      const Eigen::MatrixXd D = data[i].Q * Cd.middleRows(f0, b).transpose();  // 3·count by b
      for (int j = 0; j < b; ++j)
        for (int v = 0; v < w.part->count; ++v) {
          const Eigen::Vector3d local = rest.row(v).transpose() + D.block<3, 1>(3 * v, j);
          const Eigen::Vector3d p = L * local + t;
          worst2 = std::max(worst2, (p - frames[f0 + j].row(w.part->first + v).transpose()).squaredNorm());
        }
    }
  }
  return std::sqrt(worst2);
}

// How the weights w_fk of the basis are stored: w_fk = lo_k + span_k·t_fk with t_fk in [0, 1]; the
// constant lo_k·u_k joins the mean, span_k·u_k is stored as q_k·δ_k, and the animation's weight is
// t_fk·δ_k: never negative and at most δ_k (≤ 1 unless a component moves a vertex by more than
// 32767 units). Blender needs that: its shape keys clamp values to their slider range, [0, 1] by
// default, and its glTF importer (3.4) widens that range from the first key's weight only.
struct StoredWeights {
  Eigen::VectorXd lo, span;  // K: range of each weight column over the frames
  Eigen::VectorXd delta;     // K: value of one integer step of the stored component (1 for FLOAT)
};

// The stored basis with K components (quantized or not) and its weights (#frames by 1 + K:
// column 0 is the mean's weight 1).
void compact_data(const std::vector<WrittenPart>& written, const MorphBasis& basis, int K, bool quantize,
                  std::vector<CompactPart>* data, Eigen::MatrixXf* C, StoredWeights* sw) {
  const Eigen::MatrixXd W = basis.weights.leftCols(K);
  sw->lo = W.colwise().minCoeff().transpose();
  sw->span = (W.colwise().maxCoeff().transpose() - sw->lo).cwiseMax(1e-300);
  std::vector<Eigen::MatrixXd> U_parts;  // node-space components, scaled by their span
  for (const WrittenPart& w : written) U_parts.push_back(node_components(basis.components, w, K) * sw->span.asDiagonal());
  sw->delta = component_scales(U_parts, K, quantize);
  data->assign(written.size(), {});
  for (size_t i = 0; i < written.size(); ++i) {
    const WrittenPart& w = written[i];
    CompactPart& d = (*data)[i];
    Eigen::MatrixXd mean = basis.mean.middleRows(w.part->first, w.part->count) * w.L_inv.transpose();
    const Eigen::VectorXd shift = node_components(basis.components, w, K) * sw->lo;  // Σ lo_k u_k, stacked
    mean += Eigen::Map<const Eigen::MatrixXd>(shift.data(), 3, w.part->count).transpose();
    d.mean = mean.unaryExpr(&float_rounded);
    d.Q = U_parts[i] * sw->delta.cwiseInverse().asDiagonal();
    if (quantize) d.Q = d.Q.array().round().cwiseMax(-32767.0).cwiseMin(32767.0).matrix();
    else d.Q = d.Q.unaryExpr(&float_rounded).eval();
  }
  C->resize(W.rows(), K + 1);
  C->col(0).setOnes();
  for (int k = 0; k < K; ++k)
    C->col(k + 1) = ((W.col(k).array() - sw->lo[k]) / sw->span[k] * sw->delta[k]).cwiseMax(0.0).matrix().cast<float>();
}

// NORMAL deltas of the compact targets: mean over the frames and, per component, the
// least-squares fit on the weights (weights of different components are orthogonal with zero
// mean, so n_k = Σ_f w_fk ΔN_f / σ_k²), per unit of stored weight. Frames in blocks of 32.
void compact_normals(const std::vector<WrittenPart>& written, const MorphBasis& basis, const Eigen::MatrixXf& C,
                     const StoredWeights& sw,
                     const std::vector<Eigen::MatrixXd>& frames, const Eigen::MatrixXi& F, const Eigen::VectorXi& group,
                     int groups, int K, std::vector<CompactPart>* data, double* max_angle) {
  const int nframes = static_cast<int>(frames.size());
  assert(K <= C.cols() - 1 && "at most the written components");
  const Eigen::MatrixXd W = basis.weights.leftCols(K);
  for (size_t i = 0; i < written.size(); ++i) {
    (*data)[i].N_mean = Eigen::MatrixXd::Zero(written[i].part->count, 3);
    (*data)[i].N_Q = Eigen::MatrixXd::Zero(3 * written[i].part->count, K);
  }
  // Pass 1: accumulate. Pass 2: the largest angle between a frame's normal and the morphed one.
  for (int pass = 0; pass < 2; ++pass)
    for (int f0 = 0; f0 < nframes; f0 += 32) {
      const int b = std::min(32, nframes - f0);
      std::vector<Eigen::MatrixXd> N(b);
      for (int j = 0; j < b; ++j) N[j] = seam_normals(frames[f0 + j], F, group, groups);
      for (size_t i = 0; i < written.size(); ++i) {
        const WrittenPart& w = written[i];
        CompactPart& d = (*data)[i];
        const int count = w.part->count;
        Eigen::MatrixXd dN(3 * count, b);  // columns: stacked node-space normal deltas
        for (int j = 0; j < b; ++j) {
          const Eigen::MatrixXd n = node_normals(N[j], w);
          for (int v = 0; v < count; ++v) dN.block<3, 1>(3 * v, j) = (n.row(v) - (pass ? Eigen::RowVector3d::Zero() : Eigen::RowVector3d(w.N_base.row(v)))).transpose();
        }
        if (pass == 0) {
          for (int j = 0; j < b; ++j)
            for (int v = 0; v < count; ++v) d.N_mean.row(v) += dN.block<3, 1>(3 * v, j).transpose() / double(nframes);
          d.N_Q.noalias() += dN * W.middleRows(f0, b);
          continue;
        }
        const Eigen::MatrixXd P = d.N_Q * C.block(f0, 1, b, K).cast<double>().transpose();
        for (int j = 0; j < b; ++j)
          for (int v = 0; v < count; ++v) {
            const Eigen::Vector3d m = (w.N_base.row(v) + d.N_mean.row(v)).transpose() + P.block<3, 1>(3 * v, j);
            const Eigen::Vector3d e = dN.block<3, 1>(3 * v, j);
            if (m.squaredNorm() > 0) *max_angle = std::max(*max_angle, std::acos(std::clamp(m.normalized().dot(e), -1.0, 1.0)));
          }
      }
      if (pass == 0 && f0 + b >= nframes)
        for (size_t i = 0; i < data->size(); ++i) {
          CompactPart& d = (*data)[i];
          for (int k = 0; k < K; ++k) {
            d.N_Q.col(k) /= basis.sigma[k] * basis.sigma[k];  // per unit of w
            const Eigen::VectorXd n = d.N_Q.col(k);
            d.N_mean += sw.lo[k] * Eigen::Map<const Eigen::MatrixXd>(n.data(), 3, written[i].part->count).transpose();
            d.N_Q.col(k) *= sw.span[k] / sw.delta[k];  // per unit of stored weight
          }
        }
    }
}

// Compact layout: the smallest K whose stored data stays within the tolerance.
Status add_compact_morphs(tinygltf::Model* m, const std::vector<SurfacePart>& parts, const Eigen::MatrixXi& F,
                          const Eigen::MatrixXd& V_rest, const std::vector<Eigen::MatrixXd>& frames,
                          const std::vector<double>& times, const MorphAnimationOptions& opt, MorphAnimationReport* report) {
  if (m->buffers.empty()) m->buffers.emplace_back();
  MorphBasisOptions bo;
  bo.max_components = opt.max_components;
  const MorphBasis basis = morph_basis(frames, V_rest, bo);
  if (!basis.status.ok()) return basis.status;
  const double size = V_rest.rows() ? (V_rest.colwise().maxCoeff() - V_rest.colwise().minCoeff()).maxCoeff() : 0.0;
  const double tol = opt.tolerance * size;
  int groups = 0;
  const Eigen::VectorXi group = position_groups(V_rest, &groups);
  const Eigen::MatrixXd N_rest = opt.normals ? seam_normals(V_rest, F, group, groups) : Eigen::MatrixXd();
  const SurfaceMorphs s = surface_morphs(m, parts, V_rest, N_rest);
  const int K_max = static_cast<int>(basis.sigma.size());
  // Start from the float bound with 5% left for storage, then grow K until the stored data
  // meets the tolerance; SHORT storage is dropped if even K_max does not meet it with SHORT.
  const int K_float = morph_basis_size(basis, 0.95 * tol);
  std::vector<CompactPart> data;
  Eigen::MatrixXf C;
  StoredWeights sw;
  double error = 0;
  int K = 0;
  bool quantize = opt.quantize;
  for (;;) {
    K = K_float < 0 ? K_max : K_float;
    for (;;) {
      compact_data(s.written, basis, K, quantize, &data, &C, &sw);
      error = compact_error(s.written, data, frames, C);
      if (error <= tol || K >= K_max) break;
      K = std::min(K_max, K + std::max(1, K / 8));
    }
    if (error <= tol || !quantize) break;
    quantize = false;
  }
  double normal_angle = 0;
  const int K_N = std::clamp(opt.normal_components, 0, K);
  if (opt.normals) compact_normals(s.written, basis, C, sw, frames, F, group, groups, K_N, &data, &normal_angle);
  for (size_t i = 0; i < s.written.size(); ++i) {
    const WrittenPart& w = s.written[i];
    const CompactPart& d = data[i];
    tinygltf::Primitive& prim = m->meshes[w.part->mesh].primitives[w.part->primitive];
    std::map<std::string, int> mean;
    mean["POSITION"] = gltf_append_float_accessor(m, 0, d.mean, true);
    if (opt.normals) mean["NORMAL"] = gltf_append_float_accessor(m, 0, d.N_mean, false);
    prim.targets.push_back(mean);
    const int zero_normals = opt.normals && K_N < K ? gltf_append_float_accessor(m, 0, Eigen::MatrixXd::Zero(w.part->count, 3), false) : -1;
    for (int k = 0; k < K; ++k) {
      const Eigen::MatrixXd q = Eigen::Map<const Eigen::MatrixXd>(d.Q.col(k).data(), 3, w.part->count).transpose();
      std::map<std::string, int> target;
      target["POSITION"] = quantize ? gltf_append_short_vec3_accessor(m, 0, q) : gltf_append_float_accessor(m, 0, q, true);
      if (opt.normals && k >= K_N) target["NORMAL"] = zero_normals;
      if (opt.normals && k < K_N) {
        const Eigen::MatrixXd n = Eigen::Map<const Eigen::MatrixXd>(d.N_Q.col(k).data(), 3, w.part->count).transpose();
        target["NORMAL"] = gltf_append_float_accessor(m, 0, n, false);
      }
      prim.targets.push_back(target);
    }
  }
  if (Status st = pad_other_primitives(m, s, K + 1); !st.ok()) return st;
  add_weights_animation(m, parts, s, C, times, opt.animation_name);
  if (quantize) {
    for (auto* list : {&m->extensionsUsed, &m->extensionsRequired})
      if (std::find(list->begin(), list->end(), "KHR_mesh_quantization") == list->end()) list->push_back("KHR_mesh_quantization");
  }
  report->compact = true;
  report->targets = K + 1;
  report->components = K;
  report->size = size;
  report->max_error = size > 0 ? error / size : error;
  report->capped = error > tol;
  report->quantized = quantize;
  report->normal_error = normal_angle;
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
                             const std::vector<NodeTrack>& tracks, MorphAnimationReport* report) {
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
  MorphAnimationReport local_report;
  if (!report) report = &local_report;
  const bool compact = opt.layout == MorphExport::Compact ||
                       (opt.layout == MorphExport::Auto && static_cast<int>(frames.size()) > opt.compact_min_frames);
  Status s = compact ? add_compact_morphs(&m, parts, F, V_rest, frames, times, opt, report)
                     : add_frame_morphs(&m, parts, F, V_rest, frames, times, opt, report);
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
