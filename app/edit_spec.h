// Edit specs: the JSON document that names the region of interest, the handles with their
// transforms and the fixed vertices of an edit (used by `meshmorph edit --spec` and by the wasm
// session). Parsing only — no file I/O; lengths are in mesh units unless a field says *_rel
// (then × bounding-box diagonal).
//
//   {
//     "roi":     SELECTION,                       optional; default: the handles' components
//     "fixed":   SELECTION,                       optional
//     "handles": [ { "select": SELECTION, TRANSFORM }, ... ],      at least one
//     "features": "keep" | "scale",               Eq. 9 / Eq. 10 (default "keep")
//     "options": { "method": "naive", "coherence_rings": 1, ... }      any option of the edit
//                                  job's schema (app/edit_job.h; `meshmorph edit --help` lists them)
//   }
//   SELECTION: [i, j, ...]  or  { "indices": [...], "spheres": [{"center": [x,y,z] | "vertex": i,
//              "radius": r | "radius_rel": r}], "boxes": [{"min": [..], "max": [..]}],
//              "rings": [{"vertex": i, "k": 2}], "disks": [{"vertex": i, "radius" | "radius_rel": r}],
//              "slabs": [{"axis": "x" | "y" | "z" | "long", "from": 0.9, "to": 1.0}] }  (a union)
//   TRANSFORM: x ↦ p + t + s·R(axis, angle)·(x − p), fields (all optional):
//              "translate": [x,y,z] | "translate_rel": [..],
//              "rotate": { "axis": [x,y,z], "degrees": d | "radians": r },
//              "pivot": [x,y,z] | "centroid" (default: the centroid of the handle's rest vertices),
//              "scale": s (> 0)
//              or "matrix": [16 numbers], a 4x4 affine matrix in column-major order (three.js
//              Matrix4.elements), for drags driven by a gizmo.
// Unknown keys are errors (a typo must not silently do nothing). Status: ParseError for malformed
// JSON or wrong types, InvalidArgument for values out of range or selections that select nothing.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "edit/laplacian_editor.h"

namespace mm {

struct EditSpec {
  EditRegion region;
  std::vector<HandleTransform> transforms;  // one per handle (identity when the spec gives none)
  LaplacianEditOptions options;
  FeatureSize features = FeatureSize::Keep;
};

struct EditSpecResult {
  Status status;
  EditSpec spec;
};

// V: #V by 3 rest positions, F: #F by 3 (selections are evaluated on them).
EditSpecResult parse_edit_spec(const std::string& json_text, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

struct HandleTransformsResult {
  Status status;
  std::vector<HandleTransform> transforms;
};

// A JSON array with one TRANSFORM object per handle of `region` (pivots default to the handle
// centroids in V). Used for drags after the session was created.
HandleTransformsResult parse_handle_transforms(const std::string& json_text, const Eigen::MatrixXd& V,
                                               const EditRegion& region);

}  // namespace mm
