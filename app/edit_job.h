// The edit job (paper 001, implicit Laplacian editing): its options schema, and the whole job on
// files — load the mesh and the JSON edit spec (app/edit_spec.h), precompute, drag the handles to
// the spec's transforms, finalize (shear removal, Eq. 9/10), write the result keeping the rest of
// the input document, and report timings and quality metrics.
#pragma once

#include <functional>
#include <string>

#include "app/option_schema.h"
#include "common/progress.h"
#include "common/status.h"
#include "edit/laplacian_editor.h"

namespace mm::app {

// The options of one edit: the editor's (LaplacianEditOptions, paper defaults) and the finalize's
// feature handling (Eq. 9 keep / Eq. 10 scale).
struct EditJobOptions {
  LaplacianEditOptions editor;
  FeatureSize features = FeatureSize::Keep;
};

const OptionSchema<EditJobOptions>& edit_options();

// The editing-session options every job built on the editor shares (weights, coherence, degenerate
// vertices, finalize), added to a job's schema with `editor` reaching its LaplacianEditOptions.
template <class O>
void add_editor_options(OptionSchema<O>& s, std::function<LaplacianEditOptions&(O&)> editor) {
  s.template choice<LaplacianWeights>("weights", [editor](O& o) -> LaplacianWeights& { return editor(o).weights; },
                                      {{"cotangent", LaplacianWeights::Cotangent}, {"uniform", LaplacianWeights::Uniform}},
                                      "Laplacian weights D of Eq. 1");
  s.integer("coherence_rings", [editor](O& o) -> int& { return editor(o).coherence_rings; }, 1, 3,
            "neighbour pairs of the coherence term within this many edges (Eq. 6)");
  s.number("coherence_weight", [editor](O& o) -> double& { return editor(o).coherence_weight; }, 1e-12, kUnbounded,
           "weight of E_R relative to E_L (Eq. 6)");
  s.number("condition_threshold", [editor](O& o) -> double& { return editor(o).condition_threshold; }, 1, kUnbounded,
           "a vertex is degenerate when cond(V_i V_iᵀ) exceeds this (Sec. 3.3)");
  s.number("displacement_scale", [editor](O& o) -> double& { return editor(o).displacement_scale; }, 0, kUnbounded,
           "s_disp of Eq. 8 for degenerate vertices");
  s.template choice<RotatedCoordinates>(
      "rotated_coordinates", [editor](O& o) -> RotatedCoordinates& { return editor(o).rotated_coordinates; },
      {{"per_edge", RotatedCoordinates::PerEdge}, {"per_vertex", RotatedCoordinates::PerVertex}},
      "finalize: Laplacian coordinates rotated per edge or per vertex (Eq. 9/10)");
  s.integer("finalize_refinements", [editor](O& o) -> int& { return editor(o).finalize_refinements; }, 0, 100,
            "local/global passes after the finalize solve (per_edge only)");
}

struct EditJobFiles {
  std::string in;    // mesh to edit
  std::string spec;  // JSON edit spec
  std::string out;   // result, format by extension
};

struct EditJobResult {
  Status status;
  EditStats stats;
  int vertices = 0, handles = 0;
  double precompute_ms = 0, drag_ms = 0, finalize_ms = 0;
  bool finalized = false;
  double rigidity_error = 0;                   // mean local rigidity error (metrics/edit_metrics.h)
  double edge_distortion_mean = 0, edge_distortion_max = 0;
  int inverted_faces = 0;
};

// `overrides` holds options given outside the spec (CLI flags); they win over the spec's
// "options". `set_overrides(o)` applies them after the spec was read. preview_only: write the
// Eq. 7 solve without finalize.
struct EditJobRequest {
  EditJobFiles files;
  std::function<Status(EditJobOptions&)> set_overrides;
  bool preview_only = false;
};

EditJobResult run_edit_job(const EditJobRequest& request, const Progress& progress = {});

std::string edit_summary(const EditJobResult& r, const std::string& out_path);

}  // namespace mm::app
