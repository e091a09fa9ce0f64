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
