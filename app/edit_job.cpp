#include "app/edit_job.h"

#include <chrono>
#include <cstdio>

#include "app/edit_spec.h"
#include "io/asset.h"
#include "metrics/edit_metrics.h"

namespace mm::app {

const OptionSchema<EditJobOptions>& edit_options() {
  using O = EditJobOptions;
  static const OptionSchema<O> schema = [] {
    OptionSchema<O> s("edit", "move handles; details follow (implicit Laplacian editing, paper 001)");
    s.choice<EditMethod>("method", [](O& o) -> EditMethod& { return o.editor.method; },
                         {{"implicit", EditMethod::Implicit}, {"naive", EditMethod::NaiveLaplacian}},
                         "implicit: the paper; naive: Laplacian editing with unrotated coordinates (baseline)");
    s.choice<FeatureSize>("features", [](O& o) -> FeatureSize& { return o.features; },
                          {{"keep", FeatureSize::Keep}, {"scale", FeatureSize::Scale}},
                          "finalize: features keep their size (Eq. 9) or follow handle scaling (Eq. 10)");
    add_editor_options<O>(s, [](O& o) -> LaplacianEditOptions& { return o.editor; });
    s.number("gradient_constraint_weight", [](O& o) -> double& { return o.editor.gradient_constraint_weight; }, 0, kUnbounded,
             "pull handle gradients towards the handle's linear part (0 = off)");
    s.number("soft_constraint_weight", [](O& o) -> double& { return o.editor.soft_constraint_weight; }, 0, kUnbounded,
             "0 = hard handle/fixed constraints (paper); > 0 = soft with this weight");
    s.boolean("handle_basis", [](O& o) -> bool& { return o.editor.handle_basis; },
              "precompute a per-handle basis so that drags are a small dense product");
    s.integer("residual_refinements", [](O& o) -> int& { return o.editor.residual_refinements; }, 0, 10,
              "iterative-refinement steps of each solve against the unsquared system (0 = off)");
    return s;
  }();
  return schema;
}

EditJobResult run_edit_job(const EditJobRequest& request, const Progress& progress) {
  EditJobResult r;
  const EditJobFiles& f = request.files;
  if (!(r.status = io::check_output_path(f.out)).ok()) return r;
  std::vector<uint8_t> spec_bytes;
  if (!(r.status = io::read_file(f.spec, &spec_bytes)).ok()) return r;
  const io::LoadResult lr = io::load_asset(f.in);
  if (!(r.status = lr.status).ok()) return r;
  const Mesh m = lr.asset.mesh();
  EditSpecResult sr = parse_edit_spec(std::string(spec_bytes.begin(), spec_bytes.end()), m.V, m.F);
  if (!sr.status.ok()) {
    r.status = Status::error(sr.status.code, f.spec + ": " + sr.status.message);
    return r;
  }
  EditSpec& spec = sr.spec;
  EditJobOptions options{spec.options, spec.features};
  if (request.set_overrides && !(r.status = request.set_overrides(options)).ok()) return r;

  using clock = std::chrono::steady_clock;
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  const auto t0 = clock::now();
  LaplacianEditor editor;
  if (!(r.status = editor.precompute(m.V, m.F, spec.region, options.editor, progress)).ok()) return r;
  const auto t1 = clock::now();
  EditResult e = editor.drag(spec.transforms);
  if (!(r.status = e.status).ok()) return r;
  const auto t2 = clock::now();
  r.finalized = !request.preview_only && options.editor.method == EditMethod::Implicit;
  if (r.finalized) {
    e = editor.finalize(options.features);
    if (!(r.status = e.status).ok()) return r;
  }
  const auto t3 = clock::now();
  if (!(r.status = io::save_asset(lr.asset, e.V, f.out)).ok()) return r;

  r.stats = editor.stats();
  r.vertices = m.num_vertices();
  r.handles = static_cast<int>(spec.region.handles.size());
  r.precompute_ms = ms(t0, t1);
  r.drag_ms = ms(t1, t2);
  r.finalize_ms = ms(t2, t3);
  const EdgeDistortion d = edge_length_distortion(m.V, e.V, m.F);
  r.rigidity_error = local_rigidity_error(m.V, e.V, m.F).mean();
  r.edge_distortion_mean = d.mean;
  r.edge_distortion_max = d.max;
  r.inverted_faces = static_cast<int>(inverted_faces(m.V, e.V, m.F).size());
  return r;
}

std::string edit_summary(const EditJobResult& r, const std::string& out_path) {
  const EditStats& st = r.stats;
  char buf[768];
  std::snprintf(buf, sizeof buf,
                "edit: %d vertices, %d handle(s), %d free, %d degenerate (%d displaced)\n"
                "  precompute %.0f ms (factor %.0f ms), drag %.1f ms, %s %.1f ms\n"
                "  local rigidity error mean %.4f, edge-length distortion mean %.4f max %.4f, inverted faces %d\n"
                "  wrote %s\n",
                r.vertices, r.handles, st.free_vertices, st.degenerate_vertices, st.displaced_vertices, r.precompute_ms,
                st.factor_ms, r.drag_ms, r.finalized ? "finalize" : "no finalize", r.finalize_ms, r.rigidity_error,
                r.edge_distortion_mean, r.edge_distortion_max, r.inverted_faces, out_path.c_str());
  return buf;
}

}  // namespace mm::app
