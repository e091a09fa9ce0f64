#include "retarget/harmonic_retarget.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "linalg/polar.h"
#include "linalg/rigid_fit.h"
#include "mesh/mesh.h"
#include "retarget/bone_correspondence.h"
#include "retarget/mfs_kernel.h"
#include "spatial/triangle_bvh.h"

namespace mm {

namespace retarget_detail {

Eigen::RowVector3d bbox_center(const Eigen::MatrixXd& V) {
  return 0.5 * (V.colwise().minCoeff() + V.colwise().maxCoeff());
}

// Rotation R with R·t ≈ s for the joints (Kabsch, linalg/rigid_fit.h), snapped to the nearest of
// the 24 axis-aligned rotations: files differ by axis conventions (Y-up vs Z-up, facing ±X/±Z),
// while a general rotation fitted to joints of differently shaped characters would be noise (a
// walk would come out slightly sideways). Identity when the joints do not fix a rotation.
RigidFitOptions snapped_alignment_options() {
  RigidFitOptions o;
  o.snap_to_axes = true;
  o.min_spread = 1e-6;
  return o;
}

Eigen::MatrixXd to_working(const Eigen::MatrixXd& V, const Eigen::RowVector3d& c, double L, const Eigen::Matrix3d& R) {
  return ((V.rowwise() - c) / L) * R.transpose();
}

// A skin usable for the base: one row per surface vertex, finite weights.
bool usable_skin(const SkinWeights& skin, Eigen::Index rows) {
  return skin.index.rows() == rows && skin.weight.rows() == rows && skin.index.cols() == skin.weight.cols() &&
         skin.index.cols() > 0 && skin.weight.allFinite();
}

// Per joint of J: the base bones (child, parent) whose parent end is the joint's nearest used
// ancestor (itself included; used_of maps J's rows to used joints, −1 = not used) — the bones
// that joint's motion drives. Empty where no ancestor is used.
std::vector<std::vector<int>> joint_drives(const JointSet& J, const std::vector<int>& used_of,
                                           const std::vector<std::pair<int, int>>& bones) {
  const int nj = J.size();
  const bool tree = static_cast<int>(J.parent.size()) == nj;
  std::vector<std::vector<int>> drives(nj);
  for (int j = 0; j < nj; ++j) {
    int u = j;
    for (int guard = 0; u >= 0 && used_of[u] < 0 && guard <= nj; ++guard) u = tree ? J.parent[u] : -1;
    if (u < 0 || used_of[u] < 0) continue;
    for (size_t b = 0; b < bones.size(); ++b)
      if (bones[b].second == used_of[u]) drives[j].push_back(static_cast<int>(b));
  }
  return drives;
}

}  // namespace retarget_detail

Status HarmonicRetargeter::precompute(const RetargetCharacter& source, const RetargetCharacter& target,
                                      const std::map<std::string, std::string>& source_to_target,
                                      const HarmonicRetargetOptions& opt, const Progress& progress) {
  using namespace retarget_detail;
  ready_ = false;
  opt_ = opt;
  warnings_.clear();
  used_.clear();
  bones_.clear();
  bone_desc_.clear();
  for (const auto* c : {&source, &target}) {
    const char* side = c == &source ? "source" : "target";
    if (c->V.rows() == 0 || c->F.rows() == 0)
      return Status::error(StatusCode::InvalidMesh, std::string("the ") + side + " surface is empty");
    if (!c->V.allFinite())
      return Status::error(StatusCode::InvalidMesh, std::string("the ") + side + " surface has non-finite coordinates");
    if (c->F.minCoeff() < 0 || c->F.maxCoeff() >= c->V.rows())
      return Status::error(StatusCode::InvalidMesh, std::string("the ") + side + " faces index missing vertices");
    if (c->joints.size() == 0)
      return Status::error(StatusCode::InvalidArgument,
                           std::string("the ") + side + " has no joints" +
                               (c == &target ? " (give the target's joints as a JSON file {\"name\": [x, y, z]})" : ""));
    if (c->joints.P.rows() != c->joints.size() || !c->joints.P.allFinite())
      return Status::error(StatusCode::InvalidArgument, std::string("the ") + side + " joint positions are invalid");
  }
  JointMatchResult match = match_joints(source.joints, target.joints, source_to_target, 2);
  if (!match.status.ok()) return match.status;
  for (auto& w : match.warnings) warnings_.push_back(w);

  // Working frames.
  cs_ = bbox_center(source.V);
  ct_ = bbox_center(target.V);
  Ls_ = bounding_box_diagonal(source.V);
  Lt_ = bounding_box_diagonal(target.V);
  {
    Eigen::MatrixXd S(match.pairs.size(), 3), T(match.pairs.size(), 3);
    for (size_t i = 0; i < match.pairs.size(); ++i) {
      S.row(i) = source.joints.P.row(match.pairs[i].source);
      T.row(i) = target.joints.P.row(match.pairs[i].target);
    }
    R_ = opt.align_axes ? fit_rigid(T, S, snapped_alignment_options()).R : Eigen::Matrix3d::Identity();
  }
  const Eigen::MatrixXd Xs = to_working(source.V, cs_, Ls_, Eigen::Matrix3d::Identity());
  const Eigen::MatrixXd Xt = to_working(target.V, ct_, Lt_, R_);
  const Eigen::MatrixXd JsAll = to_working(source.joints.P, cs_, Ls_, Eigen::Matrix3d::Identity());
  const Eigen::MatrixXd JtAll = to_working(target.joints.P, ct_, Lt_, R_);

  // Inside/outside classification of joints.
  const TriangleBvh bvh_s(Xs, source.F), bvh_t(Xt, target.F);
  const double tol2 = opt.joint_tolerance * opt.joint_tolerance;  // working units: diagonal 1
  auto is_inside = [&](const TriangleBvh& bvh, const Eigen::Vector3d& p) {
    return bvh.closest_point(p).sq_distance <= tol2 || bvh.inside(p);
  };
  for (const JointPair& jp : match.pairs) {
    const std::string& name = source.joints.names[jp.source];
    if (!is_inside(bvh_s, JsAll.row(jp.source).transpose())) {
      warnings_.push_back("source joint '" + name + "' lies outside the source surface and is not used");
      continue;
    }
    const Eigen::Vector3d pt = JtAll.row(jp.target).transpose();
    if (!is_inside(bvh_t, pt)) {
      const double d = std::sqrt(bvh_t.closest_point(pt).sq_distance);
      const std::string msg = "target joint '" + target.joints.names[jp.target] + "' lies outside the target surface (" +
                              std::to_string(d * 100).substr(0, 5) + "% of the target size away)";
      if (target.joints.from_user) return Status::error(StatusCode::InvalidArgument, msg + "; move it inside the mesh");
      warnings_.push_back(msg + " and is not used");
      continue;
    }
    used_.push_back(jp);
  }
  if (used_.size() < 2)
    return Status::error(StatusCode::InvalidArgument,
                         "fewer than 2 matched joints lie inside both surfaces (" + std::to_string(used_.size()) + ")");
  const int m = static_cast<int>(used_.size());
  Js_rest_.resize(m, 3);
  Jt_rest_.resize(m, 3);
  for (int i = 0; i < m; ++i) {
    Js_rest_.row(i) = JsAll.row(used_[i].source);
    Jt_rest_.row(i) = JtAll.row(used_[i].target);
  }

  // Bones: each used joint to its nearest used ancestor in the source hierarchy.
  const bool has_tree = static_cast<int>(source.joints.parent.size()) == source.joints.size();
  if (!has_tree) warnings_.push_back("the source joints have no hierarchy: no bone-length term");
  std::vector<int> used_of(source.joints.size(), -1);
  for (int i = 0; i < m; ++i) used_of[used_[i].source] = i;
  if (has_tree)
    for (int i = 0; i < m; ++i) {
      int p = source.joints.parent[used_[i].source];
      for (int guard = 0; p >= 0 && used_of[p] < 0 && guard <= source.joints.size(); ++guard) p = source.joints.parent[p];
      if (p >= 0 && used_of[p] >= 0 && (Jt_rest_.row(i) - Jt_rest_.row(used_of[p])).norm() > 1e-6)
        bones_.push_back({i, used_of[p]});
    }

  // Anchor joint for E_position.
  const std::vector<int> depth = joint_depths(source.joints);
  anchor_ = -1;
  if (!opt.anchor_joint.empty()) {
    for (int i = 0; i < m; ++i)
      if (source.joints.names[used_[i].source] == opt.anchor_joint) anchor_ = i;
    if (anchor_ < 0)
      return Status::error(StatusCode::InvalidArgument,
                           "anchor joint '" + opt.anchor_joint + "' is not a matched joint inside both surfaces");
  } else {
    for (int i = 0; i < m; ++i)
      if (anchor_ < 0 || depth[used_[i].source] < depth[used_[anchor_].source]) anchor_ = i;
  }
  {
    const int up = std::clamp(opt.up_axis, 0, 2);
    const double hs = Js_rest_(anchor_, up) - Xs.col(up).minCoeff();
    const double ht = Jt_rest_(anchor_, up) - Xt.col(up).minCoeff();
    scale_ = (hs > 0.02 && ht > 0.02) ? ht / hs : 1.0;
  }

  // MFS bases.
  Status s = src_map_.build(Xs, source.F, opt.map, progress.sub(0.0, 0.4));
  if (!s.ok()) return Status{s.code, "source: " + s.message};
  s = tgt_map_.build(Xt, target.F, opt.map, progress.sub(0.4, 0.8));
  if (!s.ok()) return Status{s.code, "target: " + s.message};
  // Descriptor points: joints, then bone-interior samples kept where inside both shapes.
  std::vector<Eigen::RowVector3d> ds, dt;
  for (int i = 0; i < m; ++i) {
    ds.push_back(Js_rest_.row(i));
    dt.push_back(Jt_rest_.row(i));
  }
  for (const auto& [c, p] : bones_) {
    bone_desc_.push_back({c, p});
    for (int k = 1; k <= opt.bone_samples; ++k) {
      const double a = double(k) / (opt.bone_samples + 1);
      const Eigen::RowVector3d xs = (1 - a) * Js_rest_.row(c) + a * Js_rest_.row(p);
      const Eigen::RowVector3d xt = (1 - a) * Jt_rest_.row(c) + a * Jt_rest_.row(p);
      if (is_inside(bvh_s, xs.transpose()) && is_inside(bvh_t, xt.transpose())) {
        ds.push_back(xs);
        dt.push_back(xt);
      }
    }
  }
  // Surface descriptors: target surface points (a prefix of the FPS-ordered collocation points)
  // with their source counterparts in bone coordinates (retarget/bone_correspondence.h).
  if (opt.surface_descriptors > 0 && !bones_.empty()) {
    const SurfaceSamples& C = tgt_map_.collocation();
    const int k = std::min(opt.surface_descriptors, C.size());
    const BoneCorrespondence bc = bone_correspondence(C.P.topRows(k), bones_, Jt_rest_, Js_rest_, bvh_t, bvh_s);
    for (int i = 0; i < k; ++i) {
      if (bc.bone[i] < 0) continue;
      ds.push_back(bc.X.row(i));
      dt.push_back(C.P.row(i));
    }
  }
  Xs_desc_.resize(ds.size(), 3);
  Xt_desc_.resize(dt.size(), 3);
  for (size_t i = 0; i < ds.size(); ++i) {
    Xs_desc_.row(i) = ds[i];
    Xt_desc_.row(i) = dt[i];
  }

  if (!progress.update("synthesis", 0.8)) return cancelled_status("synthesis");
  const Eigen::MatrixXd& Q = src_map_.singularities();
  const Eigen::MatrixXd& U = tgt_map_.singularities();
  const Eigen::MatrixXd Ds_desc = mfs_gradient(Xs_desc_, Q);
  Ks_joints_ = mfs_kernel(Js_rest_, Q);
  Kt_joints_ = mfs_kernel(Jt_rest_, U);
  KtT_all_ = mfs_kernel(Xt, U).transpose();

  synth_ = HarmonicSynthesis();
  const int nd = static_cast<int>(Xt_desc_.rows());
  term_affine_ = synth_.add_term({"affine", mfs_gradient(Xt_desc_, U), opt.w_affine / nd, false});
  term_position_ = synth_.add_term({"position", Kt_joints_.row(anchor_), opt.w_position, false});
  rest_len_.resize(bones_.size());
  rest_len_world_.resize(bones_.size());
  if (!bones_.empty()) {
    Eigen::MatrixXd Ab(bones_.size(), U.rows());
    for (size_t b = 0; b < bones_.size(); ++b) {
      const auto [c, p] = bones_[b];
      rest_len_[b] = (Jt_rest_.row(c) - Jt_rest_.row(p)).norm();
      rest_len_world_[b] = rest_len_[b] * Lt_;
      Ab.row(b) = (Kt_joints_.row(c) - Kt_joints_.row(p)) / rest_len_[b];
    }
    term_bone_ = synth_.add_term({"bone", Ab, opt.w_bone / bones_.size(), false});
  } else {
    term_bone_ = -1;
  }
  {
    const SurfaceSamples& C = tgt_map_.collocation();
    const int nh = std::min(opt.num_smooth_points, C.size());
    // Collocation points are already in FPS order, so a prefix is a well-spread subset.
    // The Hessian has units 1/length: scaled by the offset distance (the shortest length the MFS
    // basis resolves) E_smooth becomes dimensionless like E_affine, so λ_smooth does not depend
    // on how far the singularities sit.
    const double ell = opt.map.singularities.offset;
    synth_.add_term({"smooth", ell * mfs_hessian(C.P.topRows(nh), U), opt.w_smooth / std::max(1, nh), true});
  }
  graph_on_ = false;
  graph_ = ContextGraphInfo();
  term_spatial_ = term_volume_ = -1;
  if (opt.context_graph) {
    if (!progress.update("context graph", 0.85)) return cancelled_status("context graph");
    s = build_context_graph(Xs, source.F, Xt, target.F, bvh_s, bvh_t, opt);
    if (!s.ok()) return s;
  }
  base_on_ = opt.articulated_base && !bones_.empty();
  if (base_on_) {
    Xt_rest_ = Xt;
    const bool use_skin = opt.base_skin_weights && usable_skin(source.skin, Xs.rows());
    // Leaf bones only with the skin: learned weights spread worse over the extra candidates
    // (Knight → Barbarian 0.0075 → 0.0094 of the height with them).
    build_base_skeleton(Xs, use_skin);
    const int nb = static_cast<int>(base_bones_.size());
    BoneBlend bv = bone_blend(Xs, base_Js_rest_, base_bones_);
    // Each bone's rigid fit: the source vertices it has a weight w > base_fit_weight in, weighed
    // by ((w − τ)/(1 − τ))² (continuous in w: no vertex enters or leaves a fit abruptly); a bone
    // without such vertices takes every vertex it has a share of, weighed by w².
    auto fit_sets = [&](const BoneBlend& w) {
      const double tau = std::clamp(opt.base_fit_weight, 0.0, 0.99);
      std::vector<std::vector<int>> set(nb), loose(nb);
      std::vector<std::vector<double>> set_w(nb), loose_w(nb);
      for (int i = 0; i < w.rows(); ++i)
        for (int k = w.ptr[i]; k < w.ptr[i + 1]; ++k) {
          const int b = w.bone[k];
          const double r = (w.w[k] - tau) / (1 - tau);
          if (r > 0) {
            set[b].push_back(i);
            set_w[b].push_back(r * r);
          }
          loose[b].push_back(i);
          loose_w[b].push_back(w.w[k] * w.w[k]);
        }
      // A small pull towards no rotation (1e-3 of the set's spread): a thin or flat set (an ear, a
      // tail tip) leaves a rotation about its degenerate axis undetermined, and a plain SVD then
      // picks it from rounding noise.
      RigidFitOptions fo;
      fo.rotation_prior = 1e-3;
      base_fits_.assign(nb, {});
      for (int b = 0; b < nb; ++b) {
        const bool tight = set[b].size() >= 4;
        const std::vector<double>& wb = tight ? set_w[b] : loose_w[b];
        base_fits_[b] = RigidFitFromRest(Xs, tight ? set[b] : loose[b],
                                         Eigen::Map<const Eigen::VectorXd>(wb.data(), static_cast<Eigen::Index>(wb.size())), fo);
      }
    };
    // Weights learned from the clip (surface only: which bones' motions explain each source
    // vertex over the sample frames), carried to the target through bone coordinates.
    std::vector<Eigen::MatrixXd> samples;
    for (const Eigen::MatrixXd& Vf : base_frames_)
      if (Vf.rows() == Xs.rows() && Vf.cols() == 3 && Vf.allFinite())
        samples.push_back(to_working(Vf, cs_, Ls_, Eigen::Matrix3d::Identity()));
    bool learned = false;
    if (use_skin) {
      // The source's own skin: each joint's weight goes to the base bones its nearest used
      // ancestor drives (the bones leaving it, its leaf bone).
      bv = skin_blend(Xs, source.skin.index, source.skin.weight, joint_drives(source.joints, used_of, base_bones_),
                      base_Js_rest_, base_bones_, bv);
      learned = true;
    } else if (!samples.empty()) {
      fit_sets(bv);  // the distance weights' fits give the sample poses' bone motions
      const BoneBlend candidates = bone_blend(Xs, base_Js_rest_, base_bones_, 3.0);
      std::vector<BoneMotions> motions;
      for (const Eigen::MatrixXd& Xf : samples) {
        Eigen::MatrixXd Jb;
        std::vector<Eigen::Matrix3d> Rf;
        motions.push_back(source_base(Xf, &Jb, &Rf));
      }
      bv = learn_bone_weights(Xs, samples, motions, candidates);
      learned = true;
    }
    fit_sets(bv);
    colloc_rest_s_ = src_map_.collocation_positions(Xs);
    if (learned) {
      const SurfaceSamples& C = src_map_.collocation();
      blend_colloc_s_ = interpolate_blend(bv, source.F, C.face, C.barycentric);
      // Each target vertex takes the weights of its counterpart on the source: the target posed
      // onto the source's rest skeleton by the bones (continuous in the vertex), then the closest
      // source point. (Bone coordinates by rays, as the surface descriptors use, gave the same
      // accuracy but jumped between builds: a ray's last-bit crossing decision moved a vertex's
      // weights wholesale.)
      const Eigen::MatrixXd Xts = articulated_points(Xt, base_Jt_rest_, base_Js_rest_, base_bones_);
      Eigen::VectorXi face(Xt.rows());
      Eigen::MatrixXd bary(Xt.rows(), 3);
      for (Eigen::Index i = 0; i < Xt.rows(); ++i) {
        const ClosestPoint cp = bvh_s.closest_point(Xts.row(i).transpose());
        face[i] = cp.face;
        bary.row(i) = cp.barycentric.transpose();
      }
      const BoneBlend fallback = bone_blend(Xt, base_Jt_rest_, base_bones_);
      blend_verts_t_ = interpolate_blend(bv, source.F, face, bary, &fallback);
      blend_verts_t_ = smooth_blend(blend_verts_t_, Xt, target.F, nb, opt.base_target_smoothing);
      if (opt.base_target_skin && usable_skin(target.skin, Xt.rows())) {
        // The target's own skin: each target joint's weight goes to the base bones its nearest
        // used ancestor (in the target's hierarchy) drives; rows it does not cover keep the
        // carried-over weights.
        std::vector<int> used_of_t(target.joints.size(), -1);
        for (int i = 0; i < m; ++i) used_of_t[used_[i].target] = i;
        blend_verts_t_ = skin_blend(Xt, target.skin.index, target.skin.weight,
                                    joint_drives(target.joints, used_of_t, base_bones_), base_Jt_rest_, base_bones_,
                                    blend_verts_t_);
      }
    } else {
      blend_colloc_s_ = bone_blend(colloc_rest_s_, base_Js_rest_, base_bones_);
      blend_verts_t_ = bone_blend(Xt, base_Jt_rest_, base_bones_);
    }
    if (graph_on_) {
      // The base at the graph's target nodes (on the surface: the vertices' weights there). The
      // volume graph needs none: with the base its right-hand side is 0 (see retarget()).
      blend_Va_ = interpolate_blend(blend_verts_t_, target.F, graph_.target_face, graph_.target_barycentric);
    }
    // Forward-kinematics order: from each root down (base bones are (child, parent) joint pairs).
    const int mb = static_cast<int>(base_Js_rest_.rows());
    std::vector<std::vector<int>> child_bones(mb);
    std::vector<char> is_child(mb, 0);
    for (int b = 0; b < nb; ++b) {
      child_bones[base_bones_[b].second].push_back(b);
      is_child[base_bones_[b].first] = 1;
    }
    fk_bones_.clear();
    joint_root_.assign(mb, -1);
    for (int r = 0; r < mb; ++r) {
      if (is_child[r]) continue;
      joint_root_[r] = r;
      std::vector<int> stack{r};
      while (!stack.empty()) {
        const int j = stack.back();
        stack.pop_back();
        for (int b : child_bones[j]) {
          fk_bones_.push_back(b);
          joint_root_[base_bones_[b].first] = r;
          stack.push_back(base_bones_[b].first);
        }
      }
    }
  }
  s = synth_.factor(opt.ridge);
  if (!s.ok()) return s;
  // Per-frame operators. Everything but the bone directions is linear in the projection
  // Ys = Uᵀ bs of the source frame (harmonic_map.h): Ws = V S⁻¹ Ys, Jsᵀ = Ds Ws, and
  // Wt = Ga Ys + gp p_anchor + Gb d̂ with Ga = N⁻¹ w_a A_aᵀ Ds V S⁻¹ (Eq. 13, 14, 18 composed).
  // The bone re-linearisation only needs the target joints, Kt_joints Wt, so it runs on
  // #joints-row products; V = Kt Wt (Eq. 6) is formed once at the end.
  {
    const Eigen::MatrixXd& VSinv = src_map_.coefficient_map();
    KsJ_ = Ks_joints_ * VSinv;
    const Eigen::MatrixXd Ga = synth_.solution_operator(term_affine_, Ds_desc * VSinv);
    const Eigen::MatrixXd gp = synth_.solution_operator(term_position_);
    KtGa_ = Kt_joints_ * Ga;
    Ktgp_ = Kt_joints_ * gp;
    Eigen::MatrixXd Gb(U.rows(), 0);
    if (term_bone_ >= 0) Gb = synth_.solution_operator(term_bone_);
    KtGb_ = Kt_joints_ * Gb;
    if (!Ga.allFinite() || !gp.allFinite() || !Gb.allFinite())
      return Status::error(StatusCode::NumericalError, "synthesis operators are not finite");
    // Stacked and transposed for the per-frame product (transposed_times_n3).
    GT_.resize(Ga.cols() + 1 + Gb.cols(), U.rows());
    GT_ << Ga.transpose(), gp.transpose(), Gb.transpose();
  }
  if (graph_on_) {
    // E_spatial (Eq. 11): B = (s·L·Pa(frame) + R·(L Va − s L Pa_rest)) / ℓ, linear in Pa(frame)
    // and in the rotated correction; E_volume (Eq. 12): B = R·δ_rest / ℓ_v.
    const Eigen::MatrixXd Lsd = Eigen::MatrixXd(Lsp_);
    const double ls = graph_sp_len_, lv = graph_vol_len_;
    Gsp_pos_ = synth_.solution_operator(term_spatial_, (graph_scale_ / ls) * Lsd);
    Gsp_corr_ = synth_.solution_operator(term_spatial_, Eigen::MatrixXd::Identity(Lsd.rows(), Lsd.rows()) / ls);
    Gvol_ = synth_.solution_operator(term_volume_, Eigen::MatrixXd::Identity(vol_delta_.rows(), vol_delta_.rows()) / lv);
    DmidVS_ = DmidVS_ * src_map_.coefficient_map();
    if (!Gsp_pos_.allFinite() || !Gsp_corr_.allFinite() || !Gvol_.allFinite())
      return Status::error(StatusCode::NumericalError, "context-graph operators are not finite");
  }
  progress.update("synthesis", 1.0);
  ready_ = true;
  return Status::success();
}

void HarmonicRetargeter::build_base_skeleton(const Eigen::MatrixXd& Xs, bool leaf_bones) {
  // The base's bones: the used bones, then one leaf bone per used joint that no bone leaves. A
  // leaf joint's own motion (a head, a hand, a lower leg whose foot hangs under an IK root, a
  // rigid part parented to that node) moves no used bone, so without a leaf bone the vertices it
  // carries follow the parent bone. Its segment runs from the joint to a tip: half the parent
  // bone further on, or (a joint without bones at all) towards the mean of the source vertices
  // nearest to it. The tips are base joints of their own (rows after the used joints).
  const int m = static_cast<int>(Js_rest_.rows());
  base_bones_ = bones_;
  base_Js_rest_ = Js_rest_;
  base_Jt_rest_ = Jt_rest_;
  if (!leaf_bones) return;
  std::vector<int> parent_bone(m, -1), child_count(m, 0);
  for (size_t b = 0; b < bones_.size(); ++b) {
    parent_bone[bones_[b].first] = static_cast<int>(b);
    ++child_count[bones_[b].second];
  }
  std::vector<Eigen::RowVector3d> tips_s, tips_t;
  Eigen::MatrixXd near_sum = Eigen::MatrixXd::Zero(m, 3);
  Eigen::VectorXi near_count = Eigen::VectorXi::Zero(m);
  double mean_len = 0;
  for (const auto& [c, p] : bones_) mean_len += (Js_rest_.row(c) - Js_rest_.row(p)).norm();
  mean_len /= std::max<size_t>(1, bones_.size());
  for (Eigen::Index i = 0; i < Xs.rows(); ++i) {
    Eigen::Index j = 0;
    (Js_rest_.rowwise() - Xs.row(i)).rowwise().squaredNorm().minCoeff(&j);
    near_sum.row(j) += Xs.row(i);
    ++near_count[j];
  }
  for (int j = 0; j < m; ++j) {
    if (child_count[j] > 0) continue;
    Eigen::RowVector3d ds, dt;
    if (parent_bone[j] >= 0) {
      const int p = bones_[parent_bone[j]].second;
      ds = 0.5 * (Js_rest_.row(j) - Js_rest_.row(p));
      dt = 0.5 * (Jt_rest_.row(j) - Jt_rest_.row(p));
    } else {
      if (near_count[j] == 0) continue;
      const Eigen::RowVector3d u = near_sum.row(j) / near_count[j] - Js_rest_.row(j);
      if (!(u.norm() > 1e-9)) continue;
      ds = 0.5 * mean_len * u.normalized();
      dt = scale_ * ds;
    }
    if (!(ds.norm() > 1e-9) || !(dt.norm() > 1e-9)) continue;
    base_bones_.push_back({m + static_cast<int>(tips_s.size()), j});
    tips_s.push_back(Js_rest_.row(j) + ds);
    tips_t.push_back(Jt_rest_.row(j) + dt);
  }
  base_Js_rest_.resize(m + tips_s.size(), 3);
  base_Jt_rest_.resize(m + tips_t.size(), 3);
  base_Js_rest_.topRows(m) = Js_rest_;
  base_Jt_rest_.topRows(m) = Jt_rest_;
  for (size_t k = 0; k < tips_s.size(); ++k) {
    base_Js_rest_.row(m + k) = tips_s[k];
    base_Jt_rest_.row(m + k) = tips_t[k];
  }
}

BoneMotions HarmonicRetargeter::source_bone_motions(const Eigen::MatrixXd& Xs) const {
  const int nb = static_cast<int>(base_bones_.size());
  BoneMotions M;
  M.R.assign(nb, Eigen::Matrix3d::Identity());
  M.t = Eigen::MatrixXd::Zero(nb, 3);
  std::vector<char> fitted(nb, 0);
  for (int b = 0; b < nb; ++b) {
    const RigidFitFromRest& fit = base_fits_[b];
    if (fit.size() < 4 || !(fit.total_weight() > 0)) continue;
    const RigidFit f = fit.fit(Xs);
    if (f.degenerate || !f.R.allFinite()) continue;
    M.R[b] = f.R;
    M.t.row(b) = f.t.transpose();
    fitted[b] = 1;
  }
  // Bones without a fit (too few or collinear vertices): the motion of the parent's bone.
  for (int b : fk_bones_) {
    if (fitted[b]) continue;
    for (int a : fk_bones_)
      if (base_bones_[a].first == base_bones_[b].second && fitted[a]) {
        M.R[b] = M.R[a];
        M.t.row(b) = M.t.row(a);
        fitted[b] = 1;
        break;
      }
  }
  return M;
}

BoneMotions HarmonicRetargeter::forward_kinematics(const std::vector<Eigen::Matrix3d>& R, const Eigen::MatrixXd& J_rest,
                                                   Eigen::MatrixXd* J) const {
  const int nb = static_cast<int>(base_bones_.size());
  for (int b : fk_bones_) {
    const auto [c, p] = base_bones_[b];
    J->row(c) = J->row(p) + (R[b] * (J_rest.row(c) - J_rest.row(p)).transpose()).transpose();
  }
  BoneMotions M;
  M.R = R;
  M.t.resize(nb, 3);
  for (int b = 0; b < nb; ++b) {
    const int p = base_bones_[b].second;
    M.t.row(b) = J->row(p) - (R[b] * J_rest.row(p).transpose()).transpose();
  }
  return M;
}

BoneMotions HarmonicRetargeter::source_base(const Eigen::MatrixXd& Xs, Eigen::MatrixXd* Js_base,
                                            std::vector<Eigen::Matrix3d>* R) const {
  const BoneMotions Mk = source_bone_motions(Xs);
  const Eigen::MatrixXd& Jr = base_Js_rest_;
  const int m = static_cast<int>(Jr.rows()), nb = static_cast<int>(base_bones_.size());
  Eigen::MatrixXd Jk = Eigen::MatrixXd::Zero(m, 3);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(m);
  for (int b = 0; b < nb; ++b)
    for (int j : {base_bones_[b].first, base_bones_[b].second}) {
      Jk.row(j) += (Mk.R[b] * Jr.row(j).transpose()).transpose() + Mk.t.row(b);
      count[j] += 1;
    }
  for (int j = 0; j < m; ++j)
    Jk.row(j) = count[j] > 0 ? Eigen::RowVector3d(Jk.row(j) / count[j]) : Eigen::RowVector3d(Jr.row(j));
  *R = Mk.R;
  for (int b = 0; b < nb; ++b) {
    const auto [c, p] = base_bones_[b];
    const Eigen::Vector3d s0 = Mk.R[b] * (Jr.row(c) - Jr.row(p)).transpose();
    const Eigen::Vector3d s1 = (Jk.row(c) - Jk.row(p)).transpose();
    if (s0.norm() > 1e-12 && s1.norm() > 1e-12)
      (*R)[b] = Eigen::Quaterniond::FromTwoVectors(s0, s1).toRotationMatrix() * Mk.R[b];
  }
  *Js_base = Jk;  // roots stay where the fits put them; FK fills the rest
  return forward_kinematics(*R, Jr, Js_base);
}

RetargetFrame HarmonicRetargeter::retarget(const Eigen::MatrixXd& V_source) const {
  RetargetFrame out;
  if (!ready_) {
    out.status = Status::error(StatusCode::InvalidArgument, "retarget called before a successful precompute");
    return out;
  }
  if (V_source.cols() != 3 || !V_source.allFinite()) {
    out.status = Status::error(StatusCode::InvalidArgument, "source frame must be #V by 3 finite positions");
    return out;
  }
  // Analysis: Ws = As⁺ bs (Eq. 13) in its factored form, Ys = Uᵀ bs and Ws = V S⁻¹ Ys; the
  // source joints f_s(J_s) = Ks Ws (Eq. 2) and the Jacobians Jsᵀ = Ds Ws (Eq. 4, 14) enter
  // through the precomposed operators.
  const Eigen::MatrixXd Xs = retarget_detail::to_working(V_source, cs_, Ls_, Eigen::Matrix3d::Identity());
  Eigen::MatrixXd bs = src_map_.collocation_positions(Xs);
  // Articulated base: the map fits what the bones' motions leave (bs − B_s). The motions: each
  // bone's rigid fit, the joints where the fits of the bones meeting there put them (mean), each
  // bone turned to point along its joints (twist from the fit), and positions by forward
  // kinematics from the roots — the same construction on the target with its own rest bones,
  // so that a character retargeted onto itself gets the same base on both sides.
  BoneMotions Ms, Mt;
  Eigen::MatrixXd Js_base, J_base;
  if (base_on_) {
    std::vector<Eigen::Matrix3d> R;
    Ms = source_base(Xs, &Js_base, &R);
    const int mb = static_cast<int>(base_Js_rest_.rows());
    bs -= apply_bone_motions(blend_colloc_s_, colloc_rest_s_, Ms);
    J_base = base_Jt_rest_;
    for (int r = 0; r < mb; ++r)
      if (joint_root_[r] == r) J_base.row(r) = base_Jt_rest_.row(r) + scale_ * (Js_base.row(r) - base_Js_rest_.row(r));
    Mt = forward_kinematics(R, base_Jt_rest_, &J_base);
    Js_base.conservativeResize(Js_rest_.rows(), 3);  // the used joints (tips dropped)
    J_base.conservativeResize(Jt_rest_.rows(), 3);
  }
  const Eigen::MatrixXd Ys = src_map_.project(bs);
  out.fit_residual = std::sqrt(std::max(0.0, bs.squaredNorm() - Ys.squaredNorm()) /
                               std::max<Eigen::Index>(1, bs.rows()));
  Eigen::MatrixXd Js_now = KsJ_ * Ys;  // f_s at the used source joints
  if (base_on_) Js_now += Js_base;

  // E_position: the anchor follows the source anchor's displacement, scaled (leg-length ratio).
  const Eigen::MatrixXd p_anchor =
      Jt_rest_.row(anchor_) + scale_ * (Js_now.row(anchor_) - Js_rest_.row(anchor_));
  // With the base every term below asks the map for the residual only (the base maps each rest
  // joint exactly to J_base).

  // E_bone, first linearisation: each target bone turns like its source bone, by the minimal
  // rotation taking the source rest bone to the fitted source bone f_s(c) − f_s(p). (The mean
  // Jacobian of the two ends would blend in the neighbouring bones' rotations at the joints.)
  const int nb = static_cast<int>(bones_.size());
  Eigen::MatrixXd dirs(nb, 3);
  for (int b = 0; b < nb; ++b) {
    const auto [c, p] = bones_[b];
    const Eigen::Vector3d s0 = (Js_rest_.row(c) - Js_rest_.row(p)).transpose();
    const Eigen::Vector3d s1 = (Js_now.row(c) - Js_now.row(p)).transpose();
    const Eigen::Vector3d t0 = (Jt_rest_.row(c) - Jt_rest_.row(p)).transpose().normalized();
    if (base_on_)
      dirs.row(b) = (Mt.R[b] * t0).transpose();  // the bone's rotation in the base
    else if (s0.norm() > 1e-12 && s1.norm() > 1e-12)
      dirs.row(b) = (Eigen::Quaterniond::FromTwoVectors(s0, s1) * t0).transpose();
    else
      dirs.row(b) = t0.transpose();
  }
  // Eq. 18 with the bone term re-linearised around the current target joints (keep each bone's
  // direction, restore its length); only the joints are needed until the last solve.
  // Bone-term right-hand side: d̂ minus the base's own bone direction (0 when the map adds
  // nothing to the bone).
  Eigen::MatrixXd base_dirs = Eigen::MatrixXd::Zero(nb, 3);
  if (base_on_)
    for (int b = 0; b < nb; ++b)
      base_dirs.row(b) = (J_base.row(bones_[b].first) - J_base.row(bones_[b].second)) / rest_len_[b];
  const Eigen::MatrixXd p_map = base_on_ ? Eigen::MatrixXd(p_anchor - J_base.row(anchor_)) : p_anchor;
  Eigen::MatrixXd Jt_fixed = KtGa_ * Ys + Ktgp_ * p_map;  // joints without the bone term
  if (base_on_) Jt_fixed += J_base;
  // Context graph (Eq. 11, 12): per frame only right-hand sides. Each bone's rotation is the polar
  // factor of the source map's Jacobian at the source bone's midpoint (Eq. 14 at that point).
  Eigen::MatrixXd W_graph;
  if (graph_on_) {
    std::vector<Eigen::Matrix3d> Rb(nb);
    for (int b = 0; b < nb; ++b) {
      if (base_on_) {  // Ys is the residual's projection then: the base's bone rotation
        Rb[b] = Mt.R[b];
        continue;
      }
      const Eigen::Matrix3d JT = DmidVS_.middleRows(3 * b, 3) * Ys;
      Rb[b] = polar_decomposition(JT.transpose()).R;
    }
    auto rotated = [&](const Eigen::MatrixXd& D, const Eigen::VectorXi& bone) {
      Eigen::MatrixXd C(D.rows(), 3);
      for (Eigen::Index i = 0; i < D.rows(); ++i)
        C.row(i) = bone[i] >= 0 ? Eigen::RowVector3d(D.row(i) * Rb[bone[i]].transpose()) : Eigen::RowVector3d(D.row(i));
      return C;
    };
    const Eigen::MatrixXd Pa = src_nodes_.positions(Xs, src_F_);
    W_graph = Gsp_pos_ * Pa + Gsp_corr_ * rotated(sp_corr_, sp_bone_);
    if (base_on_) {
      // The maps carry what the base leaves of the context graph's Laplacian coordinates. The
      // volume graph's: the base already moves it bone by bone, so E_volume (weight w_volume_base)
      // asks the residual to leave its Laplacian coordinates as the base has them (right-hand
      // side 0). Asking for the rest coordinates turned by one bone per row instead fought the
      // base's blend at the joints (CesiumMan self-retargeting 0.0058 with it).
      W_graph -= Gsp_corr_ * (Lsp_ * apply_bone_motions(blend_Va_, Va_, Mt));
    } else {
      W_graph += Gvol_ * rotated(vol_delta_, vol_bone_);
    }
    Jt_fixed += Kt_joints_ * W_graph;
  }
  Eigen::MatrixXd Jt_now = nb > 0 ? Eigen::MatrixXd(Jt_fixed + KtGb_ * (dirs - base_dirs)) : Jt_fixed;
  const int relinearisations = nb > 0 ? std::max(0, opt_.bone_iterations) : 0;
  for (int it = 0; it < relinearisations; ++it) {
    for (int b = 0; b < nb; ++b) {
      const Eigen::RowVector3d d = Jt_now.row(bones_[b].first) - Jt_now.row(bones_[b].second);
      if (d.norm() > 1e-12) dirs.row(b) = d / d.norm();
    }
    Jt_now = Jt_fixed + KtGb_ * (dirs - base_dirs);
  }
  Eigen::MatrixXd Z(GT_.rows(), 3);  // [Ys; p; d̂ − base]: Wt = [Ga gp Gb] Z
  Z << Ys, p_map, dirs - base_dirs;
  Eigen::MatrixXd Wt = transposed_times_n3(GT_, Z);
  if (graph_on_) Wt += W_graph;
  if (!Wt.allFinite()) {
    out.status = Status::error(StatusCode::NumericalError, "synthesized coefficients are not finite");
    return out;
  }
  // Eq. 6: V = Kt Wt for every target vertex, back to target units and axes.
  Eigen::MatrixXd Vw = transposed_times_n3(KtT_all_, Wt);
  if (base_on_) Vw += apply_bone_motions(blend_verts_t_, Xt_rest_, Mt);
  out.V = (Vw * R_) * Lt_;
  out.V.rowwise() += ct_;
  out.joints = (Jt_now * R_) * Lt_;
  out.joints.rowwise() += ct_;
  if (graph_on_) {
    Eigen::MatrixXd Gn = KtVa_ * Wt;
    if (base_on_) Gn += apply_bone_motions(blend_Va_, Va_, Mt);
    out.graph_nodes = (Gn * R_) * Lt_;
    out.graph_nodes.rowwise() += ct_;
  }
  out.source_joints = Js_now * Ls_;
  out.source_joints.rowwise() += cs_;
  if (!out.V.allFinite()) {
    out.status = Status::error(StatusCode::NumericalError, "retargeted positions are not finite");
    out.V.resize(0, 3);
  }
  return out;
}

}  // namespace mm
