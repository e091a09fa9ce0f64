// Bindings of core/edit (paper 001 implicit Laplacian editing) for the page's worker
// (web/src/ops/edit.js) and the node tests. Data conversion only: every number computed here
// comes from a core/ function.
//
// JS API — one stateful handle, the editing session:
//   const s = new module.EditSession();
//   s.create(positions: Float64Array|Float32Array (#V·3), indices: Uint32Array (#F·3),
//            spec: object | JSON string (app/edit_spec.h), progress?: (stage, f) => bool)
//     → {ok, handles: [vertex count per handle], vertices, stats: {free_vertices, known_vertices,
//        degenerate_vertices, displaced_vertices, widened_stencils, coherence_pairs,
//        system_nonzeros, mean_edge_length, stencil_ms, assembly_ms, factor_ms, basis_ms,
//        poisson_ms}, features: "keep"|"scale", transforms: the spec's transforms as
//        column-major 4x4 arrays (one per handle)}
//     Precomputes and factors both systems; returning false from progress cancels (Cancelled).
//   s.drag(transforms: [TRANSFORM, ...] | JSON string, one per handle; TRANSFORM as in the spec
//          or {matrix: [16 numbers, column-major]})          → {ok, positions: Float32Array (#V·3)}
//   s.dragPositions(targets: Float64Array (#V·3); only handle rows are read, preview?: bool)
//                                                            → {ok, positions: Float32Array}
//     preview = true: one plain solve, no iterative refinement (the frames of a pointer drag;
//     LaplacianEditor::drag_positions).
//   s.finalize(mode?: "keep" | "scale" (default: the spec's "features"))
//                                                            → {ok, positions: Float32Array}
//   s.dispose()  frees the editor's memory (the JS wrapper then calls s.delete()).
// Failures are {ok:false, code, message} (convert.h status_object); a stray C++ exception is
// returned as code "Internal" by the guard (guard.h) so the worker stays usable.
#include <string>
#include <vector>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "convert.h"
#include "guard.h"
#include "app/edit_spec.h"
#include "edit/laplacian_editor.h"

namespace mm::wasm {

using emscripten::val;

namespace {

std::string edit_json_text(const val& v) {
  if (v.isString()) return v.as<std::string>();
  return val::global("JSON").call<std::string>("stringify", v);
}

val edit_matrix_array(const HandleTransform& t) {
  val a = val::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      double x = r == 3 ? (c == 3 ? 1.0 : 0.0) : (c == 3 ? t.translation[r] : t.linear(r, c));
      a.set(4 * c + r, x);
    }
  return a;
}

val edit_positions(const EditResult& r) {
  if (!r.status.ok()) return status_object(r.status);
  val o = status_object(r.status);
  o.set("positions", to_float32_array(r.V));
  return o;
}

}  // namespace

class EditSession {
 public:
  static constexpr const char* kName = "EditSession";
  val create(const val& positions, const val& indices, const val& spec, const val& progress) {
    editor_ = LaplacianEditor();
    V_ = to_matrix(positions);
    F_ = to_index_matrix(indices);
    EditSpecResult sr = parse_edit_spec(edit_json_text(spec), V_, F_);
    if (!sr.status.ok()) return status_object(sr.status);
    spec_ = sr.spec;
    Status s = editor_.precompute(V_, F_, spec_.region, spec_.options, js_progress(progress));
    if (!s.ok()) return status_object(s);
    val o = status_object(s);
    val handles = val::array(), transforms = val::array();
    for (size_t h = 0; h < spec_.region.handles.size(); ++h) {
      handles.set(h, static_cast<int>(spec_.region.handles[h].size()));
      transforms.set(h, edit_matrix_array(spec_.transforms[h]));
    }
    o.set("handles", handles);
    o.set("transforms", transforms);
    o.set("vertices", static_cast<int>(V_.rows()));
    o.set("features", std::string(spec_.features == FeatureSize::Scale ? "scale" : "keep"));
    const EditStats& st = editor_.stats();
    val stats = val::object();
    stats.set("free_vertices", st.free_vertices);
    stats.set("known_vertices", st.known_vertices);
    stats.set("degenerate_vertices", st.degenerate_vertices);
    stats.set("displaced_vertices", st.displaced_vertices);
    stats.set("widened_stencils", st.widened_stencils);
    stats.set("coherence_pairs", st.coherence_pairs);
    stats.set("system_nonzeros", static_cast<double>(st.system_nonzeros));
    stats.set("mean_edge_length", st.mean_edge_length);
    stats.set("stencil_ms", st.stencil_ms);
    stats.set("assembly_ms", st.assembly_ms);
    stats.set("factor_ms", st.factor_ms);
    stats.set("basis_ms", st.basis_ms);
    stats.set("poisson_ms", st.poisson_ms);
    o.set("stats", stats);
    return o;
  }

  val drag(const val& transforms) {
    HandleTransformsResult t = parse_handle_transforms(edit_json_text(transforms), V_, spec_.region);
    if (!t.status.ok()) return status_object(t.status);
    return edit_positions(editor_.drag(t.transforms));
  }

  val dragPositions(const val& targets, const val& preview) {
    const bool quick = preview.isTrue();
    return edit_positions(editor_.drag_positions(to_matrix(targets), quick ? 0 : -1));
  }

  val finalize(const val& mode) {
    FeatureSize f = spec_.features;
    if (mode.isString()) {
      const std::string m = mode.as<std::string>();
      if (m != "keep" && m != "scale")
        return status_object(Status::error(StatusCode::InvalidArgument, "finalize mode must be \"keep\" or \"scale\""));
      f = m == "scale" ? FeatureSize::Scale : FeatureSize::Keep;
    }
    return edit_positions(editor_.finalize(f));
  }

  void dispose() {
    editor_ = LaplacianEditor();
    V_.resize(0, 3);
    F_.resize(0, 3);
    spec_ = EditSpec();
  }

 private:
  LaplacianEditor editor_;
  Eigen::MatrixXd V_;
  Eigen::MatrixXi F_;
  EditSpec spec_;
};

EMSCRIPTEN_BINDINGS(meshmorph_edit) {
  emscripten::class_<EditSession>("EditSession")
      .constructor<>()
      .function("create", guarded_method<&EditSession::create>())
      .function("drag", guarded_method<&EditSession::drag>())
      .function("dragPositions", guarded_method<&EditSession::dragPositions>())
      .function("finalize", guarded_method<&EditSession::finalize>())
      .function("dispose", guarded_method<&EditSession::dispose>());
}

}  // namespace mm::wasm
