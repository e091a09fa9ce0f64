// Bindings of the merge module (paper 001 Sec. 5, 6) for the worker (web/src/worker/ops/merge.js)
// and node tests. Conversion only; the work is core/merge through app/merge_job.
//
// JS API:
//   mergeMeshes(targetPositions (#T·3), targetIndices, sourcePositions (#S·3), sourceIndices,
//               spec: string (the merge spec JSON of app/merge_job.h, as `meshmorph merge --spec`
//               reads it; its "options" hold any option of optionSchema("merge")), progress?)
//     → {ok, positions: Float64Array, indices: Uint32Array (merged mesh), sourcePositions
//        (the deformed source, #S'·3), sourceIndices, targetMap: Int32Array (per target vertex:
//        merged index or -1), sourceOffset, stats: {targetVertices, sourceVertices,
//        refinedVertices, boundaryConstraints, degenerateVertices, ms: {precompute, solve, zip}},
//        seams: [{zipFaces, removedFaces, minAngleDeg, dihedralMaxDeg, dihedralMeanDeg, flippedFaces}]}
//   cutMesh(positions, indices, {plane: [px,py,pz,nx,ny,nz], keep?: [x,y,z]} | {disk: [vertex, radius]})
//     → {ok, positions, indices, from: Int32Array (input vertex of each output vertex, -1 new),
//        boundaryLoops}
//   boundaryLoops(indices, vertexCount) → {ok, loops: [Int32Array, ...]} (each in face orientation)
//   exportAssetWithMesh(asset, positions, indices, format = "glb") → {ok, bytes}: the loaded
//     asset's document with its geometry replaced (io::save_asset_with_mesh_to_memory).
#include <string>
#include <vector>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "app/merge_job.h"
#include "convert.h"
#include "guard.h"
#include "mesh/topology.h"

namespace mm::wasm {

using emscripten::val;

namespace {

val merge_int_array(const std::vector<int>& v) {
  Eigen::MatrixXi M(static_cast<Eigen::Index>(v.size()), 1);
  for (size_t i = 0; i < v.size(); ++i) M(static_cast<Eigen::Index>(i), 0) = v[i];
  return val::global("Int32Array").new_(to_uint32_array(M)["buffer"]);
}

val merge_meshes_js(val target_positions, val target_indices, val source_positions, val source_indices,
                    std::string spec_text, val progress) {
  app::MergeSpecResult sr = app::parse_merge_spec(spec_text);
  if (!sr.status.ok()) return status_object(sr.status);
  MergeInput in;
  in.target_V = to_matrix(target_positions);
  in.target_F = to_index_matrix(target_indices);
  in.source_V = to_matrix(source_positions);
  in.source_F = to_index_matrix(source_indices);
  in.pairs = sr.spec.pairs;
  in.source_fixed = sr.spec.fixed;
  const MergeResult r = merge_meshes(in, sr.spec.options, js_progress(progress));
  val out = status_object(r.status);
  if (!r.status.ok()) return out;
  out.set("positions", to_float64_array(r.V));
  out.set("indices", to_uint32_array(r.F));
  out.set("sourcePositions", to_float64_array(r.source_deformed));
  out.set("sourceIndices", to_uint32_array(r.source_F));
  out.set("targetMap", merge_int_array(r.target_map));
  out.set("sourceOffset", r.source_offset);
  val stats = val::object();
  stats.set("targetVertices", r.stats.target_vertices);
  stats.set("sourceVertices", r.stats.source_vertices);
  stats.set("refinedVertices", r.stats.refined_vertices);
  stats.set("boundaryConstraints", r.stats.boundary_constraints);
  stats.set("degenerateVertices", r.stats.editor.degenerate_vertices);
  val ms = val::object();
  ms.set("precompute", r.stats.precompute_ms);
  ms.set("solve", r.stats.solve_ms);
  ms.set("zip", r.stats.zip_ms);
  stats.set("ms", ms);
  out.set("stats", stats);
  val seams = val::array();
  for (const MergeSeamReport& z : r.stats.seams) {
    val s = val::object();
    s.set("zipFaces", z.zip_faces);
    s.set("removedFaces", z.removed_faces);
    s.set("minAngleDeg", z.min_angle_deg);
    s.set("dihedralMaxDeg", z.dihedral_max_deg);
    s.set("dihedralMeanDeg", z.dihedral_mean_deg);
    s.set("flippedFaces", z.flipped_faces);
    seams.call<void>("push", s);
  }
  out.set("seams", seams);
  return out;
}

val cut_mesh_js(val positions, val indices, val request) {
  app::CutJobRequest req;
  const val plane = request["plane"], disk = request["disk"], keep = request["keep"];
  if (!plane.isUndefined() && !plane.isNull()) {
    const Eigen::MatrixXd p = to_matrix(plane, 6);
    if (p.rows() != 1) return status_object(Status::error(StatusCode::InvalidArgument, "plane must hold 6 numbers"));
    req.point = p.row(0).head<3>().transpose();
    req.normal = p.row(0).tail<3>().transpose();
    if (!keep.isUndefined() && !keep.isNull()) {
      const Eigen::MatrixXd k = to_matrix(keep, 3);
      if (k.rows() != 1) return status_object(Status::error(StatusCode::InvalidArgument, "keep must hold 3 numbers"));
      req.has_keep = true;
      req.keep = k.row(0).transpose();
    }
  } else if (!disk.isUndefined() && !disk.isNull()) {
    const Eigen::MatrixXd d = to_matrix(disk, 2);
    if (d.rows() != 1) return status_object(Status::error(StatusCode::InvalidArgument, "disk must hold [vertex, radius]"));
    req.plane = false;
    req.disk_vertex = static_cast<int>(d(0, 0));
    req.disk_radius = d(0, 1);
  } else {
    return status_object(Status::error(StatusCode::InvalidArgument, "cutMesh needs {plane: [...]} or {disk: [...]}"));
  }
  const CutResult c = app::cut_mesh(to_matrix(positions), to_index_matrix(indices), req);
  val out = status_object(c.status);
  if (!c.status.ok()) return out;
  out.set("positions", to_float64_array(c.V));
  out.set("indices", to_uint32_array(c.F));
  out.set("from", merge_int_array(c.from));
  out.set("boundaryLoops", c.boundary_loops);
  return out;
}

val boundary_loops_js(val indices, int vertex_count) {
  const Eigen::MatrixXi F = to_index_matrix(indices);
  if (vertex_count < 0 || (F.size() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= vertex_count)))
    return status_object(Status::error(StatusCode::InvalidArgument, "indices out of range"));
  val out = status_object(Status::success());
  val loops = val::array();
  for (const std::vector<int>& l : boundary_loops(F, vertex_count)) loops.call<void>("push", merge_int_array(l));
  out.set("loops", loops);
  return out;
}

}  // namespace

EMSCRIPTEN_BINDINGS(meshmorph_merge) {
  bind<&merge_meshes_js>("mergeMeshes");
  bind<&cut_mesh_js>("cutMesh");
  bind<&boundary_loops_js>("boundaryLoops");
}

}  // namespace mm::wasm
