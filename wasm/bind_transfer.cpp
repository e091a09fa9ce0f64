// Bindings of the transfer module (spectral pose transfer, paper 000) for the worker
// (web/src/ops/transfer.js) and node tests. Conversion only; the work is core/transfer.
//
// JS API:
//   poseTransfer(refPositions (#V'·3), refIndices (#F'·3), srcPositions (#V·3), srcIndices (#F·3),
//                landmarks (Int32Array/Array of 2p: r0, s0, r1, s1, ...; empty for same connectivity),
//                options?, progress?: (stage, fraction) => boolean, cagePositions?, cageIndices?)
//     options: any option of the transfer job's schema (app/transfer_job.h; optionSchema("transfer")),
//       missing = default, unknown keys are an error
//     → {ok, positions: Float64Array (#V·3), gamma: Float64Array (k·k, row-major), k,
//        gammaDominance, iterations, converged, couplingIterations, cagePositions: Float64Array,
//        cageRest: Float64Array, cageIndices: Uint32Array, energy: Float64Array,
//        foldRetry: {tried, kept, resolution, firstFlips, firstSelfIntersections,
//                    inputSelfIntersections, ms} (PoseTransferOptions::fold_retry_resolution: the
//                    first result folded, the cage was built again on the finer grid),
//        flipRepair: {tried, kept, flippedBefore, movedVertices, ms} (flip_repair_rings: the
//                    result still flipped faces, their neighbourhood was solved again),
//        ms: {eigenbases, coupling, cage, mvc, optimisation, total}}
//   partTransfer(refPositions, refIndices, srcPositions, srcIndices, landmarks, parts, options?,
//                partOptions?, progress?)   hierarchical part transfer (paper 000 Sec. 4.3, issue 16)
//     parts: "auto" (proposed parts) or the text of a part file (core/io/parts_file.h)
//     options: the transfer schema's keys; partOptions: optionSchema("transfer-parts")
//     → {ok, positions: Float64Array (#V·3, final), positionsLevel1: Float64Array (#V·3),
//        level1: the level-1 transfer's fields as poseTransfer returns them (gamma, k, ms, ...),
//        partsJson: the part pairs used (part-file text, e.g. the proposals to edit),
//        parts: [{name, level, ok, message, sourceVertices: Uint32Array (the part's source
//                 vertices), sourceVertexCount, referenceVertices, subdivisions, landmarks,
//                 rotationDegrees, seamDihedralMean, seamDihedralMax, rejected, ms}],
//        folds: {reference, source, level1, result, flipsLevel1, flips} (self-intersecting
//                triangle pairs; flipped faces against the source),
//        foldRetry: as poseTransfer's, for the whole two-level run (level 1 and its parts again
//                   on the finer cage grid when the first result folds),
//        flipRepair: as poseTransfer's, on the final result,
//        ms: {level1, parts, total}}
//   transferMetrics(positionsA (#V·3), positionsB (#V·3), indices (#F·3))
//     → {ok, vertexErrorMean, vertexErrorMax, laplacianChange, edgeDistortionMean,
//        edgeDistortionMax, flippedFaces, collapsedFaces}
#include <string>
#include <vector>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "convert.h"
#include "metrics/transfer_metrics.h"
#include "app/transfer_job.h"
#include "io/parts_file.h"
#include "guard.h"

namespace mm::wasm {

using emscripten::val;

namespace {

// PoseTransferOptions::fold_retry_resolution's record (pose or part transfer).
val fold_retry_object(const FoldRetry& f) {
  val o = val::object();
  o.set("tried", f.tried);
  o.set("kept", f.kept);
  o.set("resolution", f.resolution);
  o.set("firstFlips", f.first.flipped_faces);
  o.set("firstCollapsed", f.first.collapsed_faces);
  o.set("firstSelfIntersections", f.first.self_intersections_result);
  o.set("inputSelfIntersections", f.first.self_intersections_reference + f.first.self_intersections_source);
  o.set("ms", f.ms);
  return o;
}

// PoseTransferOptions::flip_repair_rings's record (pose or part transfer).
val flip_repair_object(const FlipRepair& f) {
  val o = val::object();
  o.set("tried", f.tried);
  o.set("kept", f.kept);
  o.set("flippedBefore", f.flipped_before);
  o.set("collapsedBefore", f.collapsed_before);
  o.set("movedVertices", f.moved_vertices);
  o.set("ms", f.ms);
  return o;
}

// The level-1 fields of a pose transfer result (poseTransfer's, and partTransfer's `level1`).
void set_pose_fields(val& out, const PoseTransferResult& r) {
  Eigen::MatrixXd g = r.gamma;
  out.set("gamma", to_float64_array(g));
  out.set("k", static_cast<int>(g.rows()));
  out.set("gammaDominance", r.gamma_dominance);
  out.set("iterations", r.iterations);
  out.set("converged", r.converged);
  out.set("couplingIterations", r.coupling_iterations);
  out.set("cagePositions", to_float64_array(r.cage_deformed));
  out.set("cageRest", to_float64_array(r.cage_rest));
  out.set("cageIndices", to_uint32_array(r.cage_faces));
  out.set("energy", to_float64_array(Eigen::Map<const Eigen::MatrixXd>(r.energy.data(), r.energy.size(), 1)));
  out.set("foldRetry", fold_retry_object(r.fold_retry));
  out.set("flipRepair", flip_repair_object(r.flip_repair));
  val ms = val::object();
  ms.set("eigenbases", r.ms.eigenbases);
  ms.set("coupling", r.ms.coupling);
  ms.set("cage", r.ms.cage);
  ms.set("mvc", r.ms.mvc);
  ms.set("optimisation", r.ms.optimisation);
  ms.set("total", r.ms.total);
  out.set("ms", ms);
}

// The part pairs of a spec, depth first (the order of PartTransferResult::reports).
void flatten_parts(const std::vector<PartPair>& parts, std::vector<const PartPair*>* out) {
  for (const PartPair& p : parts) {
    out->push_back(&p);
    flatten_parts(p.children, out);
  }
}

val pose_transfer_js(val ref_positions, val ref_indices, val src_positions, val src_indices, val landmarks,
                     val options, val progress, val cage_positions, val cage_indices) {
  {
    const Mesh ref{to_matrix(ref_positions), to_index_matrix(ref_indices)};
    const Mesh src{to_matrix(src_positions), to_index_matrix(src_indices)};
    const std::vector<int> flat = to_int_vector(landmarks);
    if (flat.size() % 2 != 0)
      return status_object(Status::error(StatusCode::InvalidArgument, "landmarks must hold pairs (reference, source)"));
    std::vector<LandmarkPair> pairs;
    for (size_t i = 0; i + 1 < flat.size(); i += 2) pairs.push_back({flat[i], flat[i + 1]});
    PoseTransferOptions opt;
    if (Status os = read_options(options, app::transfer_options(), &opt); !os.ok()) return status_object(os);
    Mesh cage;
    const bool has_cage = !cage_positions.isUndefined() && !cage_positions.isNull();
    if (has_cage) cage = {to_matrix(cage_positions), to_index_matrix(cage_indices)};
    const PoseTransferResult r = pose_transfer(ref, src, pairs, opt, js_progress(progress), has_cage ? &cage : nullptr);
    val out = status_object(r.status);
    if (!r.status.ok()) return out;
    out.set("positions", to_float64_array(r.V));
    set_pose_fields(out, r);
    return out;
  }
}

val part_transfer_js(val ref_positions, val ref_indices, val src_positions, val src_indices, val landmarks, val parts,
                     val options, val part_options, val progress) {
  const Mesh ref{to_matrix(ref_positions), to_index_matrix(ref_indices)};
  const Mesh src{to_matrix(src_positions), to_index_matrix(src_indices)};
  const std::vector<int> flat = to_int_vector(landmarks);
  if (flat.size() % 2 != 0)
    return status_object(Status::error(StatusCode::InvalidArgument, "landmarks must hold pairs (reference, source)"));
  std::vector<LandmarkPair> pairs;
  for (size_t i = 0; i + 1 < flat.size(); i += 2) pairs.push_back({flat[i], flat[i + 1]});
  PartTransferOptions opt;
  if (Status os = read_options(options, app::transfer_options(), &opt.transfer); !os.ok()) return status_object(os);
  if (Status os = read_options(part_options, app::transfer_part_options(), &opt); !os.ok()) return status_object(os);
  if (!parts.isString())
    return status_object(Status::error(StatusCode::InvalidArgument, "parts must be \"auto\" or the text of a part file"));
  const std::string parts_text = parts.as<std::string>();
  PartsSpec spec;
  const bool automatic = parts_text == "auto";
  if (!automatic)
    if (Status ps = io::parse_parts(parts_text, "parts", &spec); !ps.ok()) return status_object(ps);
  const PartTransferResult r = part_transfer(ref, src, pairs, automatic ? nullptr : &spec, opt, js_progress(progress));
  val out = status_object(r.status);
  if (!r.status.ok()) return out;
  out.set("positions", to_float64_array(r.V));
  out.set("positionsLevel1", to_float64_array(r.V_level1));
  out.set("partsJson", io::parts_json(r.parts));
  out.set("proposalsTried", r.proposals_tried);
  out.set("proposalKept", r.proposal_kept);
  out.set("proposalRounds", r.proposal_rounds);
  out.set("landmarkErrorLevel1", r.landmark_error_level1);
  out.set("landmarkError", r.landmark_error);
  val list = val::array();
  // Each part's source vertices (its region on the source input mesh, whose vertex ids the
  // result shares), for the page's part colours.
  std::vector<const PartPair*> flat_parts;
  flatten_parts(r.parts.parts, &flat_parts);
  for (size_t i = 0; i < r.reports.size(); ++i) {
    const PartReport& p = r.reports[i];
    val o = val::object();
    if (flat_parts.size() == r.reports.size()) {
      std::vector<int> vertices;
      if (part_vertices(src.V, src.F, flat_parts[i]->source, &vertices).ok())
        o.set("sourceVertices", to_uint32_array(Eigen::Map<const Eigen::MatrixXi>(vertices.data(), static_cast<Eigen::Index>(vertices.size()), 1)));
    }
    o.set("name", p.name);
    o.set("level", p.level);
    o.set("round", p.round);
    o.set("ok", p.status.ok());
    o.set("message", p.status.message);
    o.set("sourceVertexCount", p.source_vertices);
    o.set("referenceVertices", p.reference_vertices);
    o.set("subdivisions", p.subdivisions);
    o.set("landmarks", p.landmarks);
    o.set("rotationDegrees", p.rotation_degrees);
    o.set("rigid", p.rigid);
    o.set("transferFlips", p.transfer_flips);
    o.set("cageReused", p.cage_reused);
    o.set("fixedCageVertices", p.fixed_cage_vertices);
    o.set("seamDihedralMean", p.seam_dihedral_mean);
    o.set("seamDihedralMax", p.seam_dihedral_max);
    o.set("rejected", p.rejected);
    o.set("ms", p.ms);
    list.call<void>("push", o);
  }
  out.set("parts", list);
  val folds = val::object();
  folds.set("reference", r.folds.self_intersections_reference);
  folds.set("source", r.folds.self_intersections_source);
  folds.set("level1", r.folds_level1.self_intersections_result);
  folds.set("result", r.folds.self_intersections_result);
  folds.set("flipsLevel1", r.folds_level1.flipped_faces);
  folds.set("flips", r.folds.flipped_faces);
  folds.set("collapsedLevel1", r.folds_level1.collapsed_faces);
  folds.set("collapsed", r.folds.collapsed_faces);
  out.set("folds", folds);
  out.set("foldRetry", fold_retry_object(r.fold_retry));
  out.set("flipRepair", flip_repair_object(r.flip_repair));
  val level1 = val::object();
  set_pose_fields(level1, r.level1);
  out.set("level1", level1);
  val ms = val::object();
  ms.set("level1", r.ms_level1);
  ms.set("parts", r.ms_parts);
  ms.set("total", r.ms_total);
  out.set("ms", ms);
  return out;
}

val transfer_metrics_js(val a, val b, val indices) {
  const TransferMetrics m = transfer_metrics(to_matrix(a), to_matrix(b), to_index_matrix(indices));
  val out = status_object(m.status);
  if (!m.status.ok()) return out;
  out.set("vertexErrorMean", m.vertex_error_mean);
  out.set("vertexErrorMax", m.vertex_error_max);
  out.set("laplacianChange", m.laplacian_change);
  out.set("edgeDistortionMean", m.edge_distortion_mean);
  out.set("edgeDistortionMax", m.edge_distortion_max);
  out.set("flippedFaces", m.flipped_faces);
  out.set("collapsedFaces", m.collapsed_faces);
  return out;
}

}  // namespace

EMSCRIPTEN_BINDINGS(meshmorph_transfer) {
  bind<&pose_transfer_js>("poseTransfer");
  bind<&part_transfer_js>("partTransfer");
  bind<&transfer_metrics_js>("transferMetrics");
}

}  // namespace mm::wasm
