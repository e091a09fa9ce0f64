#include "edit/laplacian_editor.h"

#include <cassert>
#include <chrono>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "common/threads.h"
#include "edit/laplacian_editor_impl.h"
#include "linalg/rigid_fit.h"

namespace mm {

namespace edit_detail {

// Best-fit similarity linear part (s·R) mapping rest points P to targets Q (Umeyama 1991,
// linalg/rigid_fit.h). Fewer than 3 points, or collinear points, give the identity (no rotation
// can be read off).
Eigen::Matrix3d edit_fit_similarity_linear(const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q) {
  RigidFitOptions o;
  o.scale = true;
  o.min_spread = 1e-12;
  const RigidFit fit = fit_rigid(P, Q, o);
  if (fit.degenerate) return Eigen::Matrix3d::Identity();
  return fit.s * fit.R;
}

// Milliseconds since `t0`; resets t0 to now.
double edit_lap_ms(std::chrono::steady_clock::time_point* t0) {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - *t0).count();
  *t0 = now;
  return ms;
}

}  // namespace edit_detail

using namespace edit_detail;

HandleTransform HandleTransform::similarity(const Eigen::Vector3d& translation, const Eigen::Vector3d& axis,
                                            double angle, const Eigen::Vector3d& pivot, double scale) {
  HandleTransform t;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (axis.norm() > 0) R = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  t.linear = scale * R;
  t.translation = pivot + translation - t.linear * pivot;
  return t;
}

LaplacianEditor::LaplacianEditor() : impl_(std::make_unique<Impl>()) {}
LaplacianEditor::~LaplacianEditor() = default;
LaplacianEditor::LaplacianEditor(LaplacianEditor&&) noexcept = default;
LaplacianEditor& LaplacianEditor::operator=(LaplacianEditor&&) noexcept = default;

bool LaplacianEditor::ready() const { return impl_ && impl_->ready; }
const std::vector<int>& LaplacianEditor::displaced_vertices() const { return impl_->grads.displaced; }
const EditStats& LaplacianEditor::stats() const { return impl_->stats; }

Status LaplacianEditor::precompute(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const EditRegion& region,
                                   const LaplacianEditOptions& opt, const Progress& progress) {
  impl_ = std::make_unique<Impl>();
  impl_->opt = opt;
  Status s = impl_->build(V, F, region, progress);
  if (!s.ok()) impl_ = std::make_unique<Impl>();
  return s;
}

Status LaplacianEditor::Impl::build(const Eigen::MatrixXd& Vin, const Eigen::MatrixXi& F, const EditRegion& region,
                                    const Progress& progress) {
  assert(F.cols() == 3 && "F must be triangles");
  // ---- options and inputs
  if (!(opt.coherence_rings >= 1 && opt.coherence_rings <= 3))
    return Status::error(StatusCode::InvalidArgument, "coherence_rings must be 1, 2 or 3");
  if (!(opt.finalize_refinements >= 0 && opt.finalize_refinements <= 100))
    return Status::error(StatusCode::InvalidArgument, "finalize_refinements must be between 0 and 100");
  if (!(opt.residual_refinements >= 0 && opt.residual_refinements <= 10))
    return Status::error(StatusCode::InvalidArgument, "residual_refinements must be between 0 and 10");
  if (!(opt.coherence_weight > 0) || !(opt.condition_threshold > 1) || !(opt.displacement_scale > 0) ||
      !(opt.gradient_constraint_weight >= 0) || !(opt.soft_constraint_weight >= 0) ||
      !std::isfinite(opt.coherence_weight + opt.condition_threshold + opt.displacement_scale +
                     opt.gradient_constraint_weight + opt.soft_constraint_weight))
    return Status::error(StatusCode::InvalidArgument,
                         "edit options out of range (weights must be finite and ≥ 0, coherence_weight > 0, "
                         "condition_threshold > 1, displacement_scale > 0)");
  EditBuild s;
  if (Status st = build_region(Vin, F, region, &s); !st.ok()) return st;
  if (!progress.update("edit: stencils", 0.0)) return cancelled_status("edit: stencils");
  s.clock = std::chrono::steady_clock::now();
  region_edge_scale(F, &s);
  if (Status st = build_stencils(F, &s, progress); !st.ok()) return st;
  number_locally(F, &s);
  s.Fsub.resize(s.faces.size(), 3);
  for (size_t k = 0; k < s.faces.size(); ++k) s.Fsub.row(static_cast<Eigen::Index>(k)) = F.row(s.faces[k]);
  s.cot = opt.weights == LaplacianWeights::Cotangent;
  // The Poisson system of the finalize step (Eq. 9/10) and the Eq. 7 system are independent:
  // natively, with a second thread, the Poisson factor is built beside the Eq. 7 assembly and
  // factor (it reads the region and V, writes only its own members; no progress from that
  // thread). Bit-identical either way.
  Status poisson_status = Status::success();
  Task poisson;  // declared after poisson_status: an early return waits for it first
#if MM_HAS_THREADS
  if (s.implicit && max_threads() > 1)
    poisson = Task([this, &s, &poisson_status] { poisson_status = build_finalize_system(s, Progress{}); });
#endif
  if (!poisson.valid()) {
    if (Status st = build_finalize_system(s, progress); !st.ok()) return st;
    s.clock = std::chrono::steady_clock::now();  // the Poisson stage has its own timing
  }
  if (!progress.update("edit: assembling", 0.1)) return cancelled_status("edit: assembling");
  if (s.implicit) {
    // An early return waits for the Poisson task (its destructor).
    if (Status st = build_similarity_system(s, progress); !st.ok()) return st;
    if (opt.handle_basis)
      if (Status st = build_handle_basis(s, progress); !st.ok()) return st;
  }
  if (poisson.valid()) {
    poisson.wait();
    if (!poisson_status.ok()) return poisson_status;
  }
  if (!progress.update("edit: done", 1.0)) return cancelled_status("edit: done");
  ready = true;
  return Status::success();
}

namespace {

EditResult edit_error(StatusCode code, const std::string& message) {
  EditResult r;
  r.status = Status::error(code, message);
  return r;
}

}  // namespace

EditResult LaplacianEditor::drag(const std::vector<HandleTransform>& transforms) {
  Impl& m = *impl_;
  if (!m.ready) return edit_error(StatusCode::InvalidArgument, "drag called before a successful precompute");
  if (static_cast<int>(transforms.size()) != m.num_handles)
    return edit_error(StatusCode::InvalidArgument, "got " + std::to_string(transforms.size()) +
                                                       " handle transforms for " + std::to_string(m.num_handles) +
                                                       " handles");
  for (size_t h = 0; h < transforms.size(); ++h)
    if (!transforms[h].linear.allFinite() || !transforms[h].translation.allFinite())
      return edit_error(StatusCode::InvalidArgument, "handle " + std::to_string(h) + " transform has non-finite entries");
  const int nK = m.nL - m.nU;
  auto map = [&](int g, const Eigen::RowVector3d& p) -> Eigen::RowVector3d {
    if (g < 0) return p;
    return (transforms[g].linear * p.transpose() + transforms[g].translation).transpose();
  };
  // Displacement of a displaced rest position: (A − I) v' + t, exactly zero for the identity.
  auto displacement = [&](int g, const Eigen::RowVector3d& p) -> Eigen::RowVector3d {
    if (g < 0) return Eigen::RowVector3d::Zero();
    return ((transforms[g].linear - Eigen::Matrix3d::Identity()) * p.transpose() + transforms[g].translation).transpose();
  };
  m.known.resize(nK, 3);
  Eigen::MatrixXd known_u(nK, 3);
  for (int k = 0; k < nK; ++k) {
    const int l = m.nU + k, v = m.l2g[l];
    m.known.row(k) = map(m.group[l], m.V.row(v));
    known_u.row(k) = displacement(m.group[l], m.Vd.row(v));
  }
  Eigen::MatrixXd soft_ud;
  if (m.opt.soft_constraint_weight > 0) {
    m.soft_u = Eigen::MatrixXd::Zero(m.nU, 3);
    soft_ud = Eigen::MatrixXd::Zero(m.nU, 3);
    for (int l = 0; l < m.nU; ++l)
      if (m.soft[l] > 0) {
        m.soft_u.row(l) = map(m.group[l], m.V.row(m.l2g[l]));
        soft_ud.row(l) = displacement(m.group[l], m.Vd.row(m.l2g[l]));
      }
  }
  if (m.opt.method == EditMethod::NaiveLaplacian) {
    m.have_drag = true;
    return m.solve_stage2(false, FeatureSize::Keep);
  }
  std::vector<Eigen::Matrix3d> linear(m.num_handles);
  std::vector<Eigen::Vector3d> translation(m.num_handles);
  for (int h = 0; h < m.num_handles; ++h) {
    linear[h] = transforms[h].linear;
    translation[h] = transforms[h].translation;
  }
  int refinements = 0;
  if (Status s = m.solve_stage1(known_u, soft_ud, linear, &translation, &refinements); !s.ok()) {
    EditResult r;
    r.status = s;
    return r;
  }
  m.have_drag = true;
  return m.output_stage1(refinements);
}

EditResult LaplacianEditor::drag_positions(const Eigen::MatrixXd& targets, int max_refinements) {
  Impl& m = *impl_;
  if (!m.ready) return edit_error(StatusCode::InvalidArgument, "drag_positions called before a successful precompute");
  if (targets.rows() != m.V.rows() || targets.cols() != 3)
    return edit_error(StatusCode::InvalidArgument, "targets must be #V by 3 (" + std::to_string(m.V.rows()) + " by 3)");
  // Gather each handle's rest and target points for its best-fit linear part.
  std::vector<std::vector<int>> members(m.num_handles);
  for (int l = 0; l < m.nL; ++l)
    if (m.group[l] >= 0 && (l >= m.nU || m.soft[l] > 0)) members[m.group[l]].push_back(m.l2g[l]);
  std::vector<Eigen::Matrix3d> linear(m.num_handles, Eigen::Matrix3d::Identity());
  for (int h = 0; h < m.num_handles; ++h) {
    Eigen::MatrixXd P(members[h].size(), 3), Q(members[h].size(), 3);
    for (size_t k = 0; k < members[h].size(); ++k) {
      P.row(static_cast<Eigen::Index>(k)) = m.V.row(members[h][k]);
      Q.row(static_cast<Eigen::Index>(k)) = targets.row(members[h][k]);
    }
    if (!Q.allFinite())
      return edit_error(StatusCode::InvalidArgument, "handle " + std::to_string(h) + " targets have non-finite entries");
    linear[h] = edit_fit_similarity_linear(P, Q);
  }
  const int nK = m.nL - m.nU;
  m.known.resize(nK, 3);
  Eigen::MatrixXd known_u(nK, 3);
  // Target in the original frame, and the displacement of the displaced rest position v' (whose
  // target is t + A (v' − v), the handle's linear part carrying the Eq. 8 offset):
  // (t − v) + (A − I)(v' − v), exactly zero for targets at rest with A = I.
  auto target_of = [&](int l, Eigen::RowVector3d* orig, Eigen::RowVector3d* disp) {
    const int v = m.l2g[l], g = m.group[l];
    if (g < 0) {
      *orig = m.V.row(v);
      disp->setZero();
    } else {
      *orig = targets.row(v);
      *disp = (targets.row(v) - m.V.row(v)) +
              ((linear[g] - Eigen::Matrix3d::Identity()) * (m.Vd.row(v) - m.V.row(v)).transpose()).transpose();
    }
  };
  for (int k = 0; k < nK; ++k) {
    Eigen::RowVector3d o, d;
    target_of(m.nU + k, &o, &d);
    m.known.row(k) = o;
    known_u.row(k) = d;
  }
  Eigen::MatrixXd soft_ud;
  if (m.opt.soft_constraint_weight > 0) {
    m.soft_u = Eigen::MatrixXd::Zero(m.nU, 3);
    soft_ud = Eigen::MatrixXd::Zero(m.nU, 3);
    for (int l = 0; l < m.nU; ++l)
      if (m.soft[l] > 0) {
        Eigen::RowVector3d o, d;
        target_of(l, &o, &d);
        m.soft_u.row(l) = o;
        soft_ud.row(l) = d;
      }
  }
  if (m.opt.method == EditMethod::NaiveLaplacian) {
    m.have_drag = true;
    return m.solve_stage2(false, FeatureSize::Keep);
  }
  int refinements = 0;
  if (Status s = m.solve_stage1(known_u, soft_ud, linear, nullptr, &refinements, max_refinements); !s.ok()) {
    EditResult r;
    r.status = s;
    return r;
  }
  m.have_drag = true;
  return m.output_stage1(refinements);
}

EditResult LaplacianEditor::finalize(FeatureSize mode) {
  Impl& m = *impl_;
  if (!m.ready || !m.have_drag) return edit_error(StatusCode::InvalidArgument, "finalize called before a drag");
  return m.solve_stage2(m.opt.method == EditMethod::Implicit, mode);
}

Eigen::MatrixXd LaplacianEditor::gradients() const {
  const Impl& m = *impl_;
  if (!m.ready || !m.have_drag || m.opt.method != EditMethod::Implicit) return {};
  Eigen::MatrixXd G(m.V.rows(), 9);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (int v = 0; v < G.rows(); ++v) G.row(v) = Eigen::Map<const Eigen::Matrix<double, 1, 9>>(I.data());
  for (int l = 0; l < m.nU; ++l) {
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> M = m.gradient_local(l);
    G.row(m.l2g[l]) = Eigen::Map<const Eigen::Matrix<double, 1, 9>>(M.data());
  }
  return G;
}

LaplacianEditResult laplacian_edit(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const EditRegion& region,
                                   const std::vector<HandleTransform>& transforms, const LaplacianEditOptions& opt,
                                   FeatureSize mode, bool finalize, const Progress& progress) {
  LaplacianEditResult out;
  LaplacianEditor editor;
  out.status = editor.precompute(V, F, region, opt, progress);
  if (!out.status.ok()) return out;
  out.stats = editor.stats();
  EditResult d = editor.drag(transforms);
  if (!d.status.ok()) {
    out.status = d.status;
    return out;
  }
  out.preview = d.V;
  if (!finalize) {
    out.V = d.V;
    return out;
  }
  EditResult f = editor.finalize(mode);
  out.status = f.status;
  out.V = f.V;
  return out;
}

}  // namespace mm
