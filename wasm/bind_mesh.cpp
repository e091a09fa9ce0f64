// Bindings of the mesh, io, operators and spectral modules for the page's worker
// (web/src/ops/mesh.js) and the node API tests (tests/js/). Data conversion only: every
// number computed here comes from a core/ function.
//
// JS API (all calls return plain objects; a failure is {ok:false, code, message}, see
// convert.h status_object; the JS wrapper in web/src/ops/mesh.js throws an Error carrying code):
//
//   loadAsset(bytes: Uint8Array, name: string, files?: {[uri]: Uint8Array}, options?)
//     → {ok, asset: number, name, format, warnings: string[], primitives: [...],
//        positions: Float32Array (#R·3, raw layout, world space), indices: Uint32Array (#T·3),
//        normals: Float32Array (#R·3, smooth normals of the welded surface, raw layout),
//        toWelded: Uint32Array (#R), weldedVertices: #W, weldedFaces: #F,
//        report: MeshReport object (of the welded mesh),
//        text: string and info: object (the `meshmorph info` report and its --json form,
//        io/info_report.h)}
//     `name` picks the format by extension. `files` resolves a .gltf's external buffers and
//     images by URI (exact key first, then the URI's last path segment). `options` mirrors
//     io::LoadOptions: {weld: {tolerance, drop_degenerate_faces}, skip_unsupported_primitives}.
//     The asset stays in a registry until disposeAsset(asset).
//   disposeAsset(asset: number) → boolean (false when unknown)
//   assetWeldedMesh(asset) → {ok, positions: Float64Array (#W·3), indices: Uint32Array (#F·3)}:
//     the welded mesh the algorithms work on. Not part of loadAsset's result: at 1M vertices
//     the two copies are a tenth of the load, and a page that only views the mesh never needs
//     them (worker/ops/mesh.js fetches them on first use).
//   exportAsset(asset, positions?: Float64Array|Float32Array (#W·3 welded, world space;
//               undefined keeps the loaded geometry), format = "glb", options? {recompute_normals})
//     → {ok, bytes: Uint8Array}
//   exportAssetWithMesh(asset, positions (#V·3), indices (#F·3), format = "glb") → {ok, bytes}: a
//     mesh of another topology (merge, cut) in place of the asset's geometry, document kept
//     (io::save_asset_with_mesh_to_memory).
//   saveMesh(format, positions (#V·3), indices (#F·3), colors? (#V·3 in 0..1)) → {ok, bytes}
//   validateMesh(positions (#V·3), indices (#F·3), options? {degenerate_area_tolerance})
//     → {ok: true, report, text}
//   spectralBasis(positions (#V·3), indices (#F·3), options? {k, ncv, relative_shift,
//                 tolerance, max_iterations, solver: 'auto'|'block'|'spectra'},
//                 progress?: (stage, fraction) => boolean)
//     → {ok, eigenvalues: Float64Array (k, ascending), vectors: Float32Array (k·#V; basis
//        function i occupies [i·#V, (i+1)·#V), the layout the viewer slices), iterations,
//        operations, solver ('block Lanczos', 'Spectra' or 'dense')}. Returning false from progress cancels (code "Cancelled").
//
// Exceptions: core reports data errors as Status; a stray C++ exception (bad_alloc on a huge
// file, a bug) is caught here and returned as code "Internal" so the worker stays usable.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "convert.h"
#include "guard.h"
#include "io/asset.h"
#include "io/info_report.h"
#include "mesh/validate.h"
#include "mesh/weld.h"
#include "operators/operators.h"
#include "spectral/spectral_basis.h"

namespace mm::wasm {

using emscripten::val;

namespace {

// Loaded assets by id. The worker is single-threaded and owns this module instance, so a plain
// map is enough; ids are never reused within one module instance.
std::map<int, std::unique_ptr<io::Asset>>& asset_registry() {
  static std::map<int, std::unique_ptr<io::Asset>> registry;
  return registry;
}
int g_next_asset_id = 1;

val error_object(StatusCode code, const std::string& message) {
  return status_object(Status::error(code, message));
}

std::optional<io::Format> parse_format(const std::string& name) {
  return io::format_from_path("x." + name);
}

val int_array(const std::vector<int>& v) {
  val a = val::array();
  for (size_t i = 0; i < v.size(); ++i) a.set(i, v[i]);
  return a;
}

val vec3(const Eigen::Vector3d& v) {
  val a = val::array();
  for (int i = 0; i < 3; ++i) a.set(i, v[i]);
  return a;
}

// Stable identifier of a defect for code (mesh_defect_name is the human wording).
const char* defect_id(MeshDefect d) {
  switch (d) {
    case MeshDefect::Empty: return "Empty";
    case MeshDefect::NonFiniteCoordinate: return "NonFiniteCoordinate";
    case MeshDefect::IndexOutOfRange: return "IndexOutOfRange";
    case MeshDefect::DegenerateFace: return "DegenerateFace";
    case MeshDefect::DuplicateFace: return "DuplicateFace";
    case MeshDefect::NonManifoldEdge: return "NonManifoldEdge";
    case MeshDefect::NonManifoldVertex: return "NonManifoldVertex";
    case MeshDefect::UnreferencedVertex: return "UnreferencedVertex";
    case MeshDefect::InconsistentOrientation: return "InconsistentOrientation";
  }
  return "Unknown";
}

val report_object(const MeshReport& r) {
  val o = val::object();
  o.set("vertices", r.num_vertices);
  o.set("faces", r.num_faces);
  o.set("edges", r.num_edges);
  o.set("bboxMin", vec3(r.bbox_min));
  o.set("bboxMax", vec3(r.bbox_max));
  o.set("bboxDiagonal", r.bbox_diagonal);
  o.set("components", r.num_components);
  o.set("componentSizes", int_array(r.component_sizes));
  std::vector<int> loop_lengths;
  for (const auto& loop : r.boundary_loops) loop_lengths.push_back(static_cast<int>(loop.size()));
  o.set("boundaryLoopLengths", int_array(loop_lengths));
  o.set("eulerCharacteristic", r.euler_characteristic);
  o.set("closed", r.closed());
  val defects = val::array();
  for (size_t i = 0; i < r.defects.size(); ++i) {
    val d = val::object();
    d.set("id", std::string(defect_id(r.defects[i].defect)));
    d.set("name", std::string(mesh_defect_name(r.defects[i].defect)));
    d.set("count", r.defects[i].count);
    d.set("example", r.defects[i].example);
    defects.set(i, d);
  }
  o.set("defects", defects);
  return o;
}

val primitives_array(const io::Asset& a) {
  val out = val::array();
  for (size_t i = 0; i < a.primitives.size(); ++i) {
    const io::PrimitiveRef& p = a.primitives[i];
    val o = val::object();
    o.set("name", p.name);
    o.set("node", p.node);
    o.set("mesh", p.mesh);
    o.set("primitive", p.primitive);
    o.set("firstVertex", p.first_vertex);
    o.set("numVertices", p.num_vertices);
    o.set("firstFace", p.first_face);
    o.set("numFaces", p.num_faces);
    o.set("skinned", p.skinned);
    out.set(i, o);
  }
  return out;
}

val string_array(const std::vector<std::string>& v) {
  val a = val::array();
  for (size_t i = 0; i < v.size(); ++i) a.set(i, v[i]);
  return a;
}

std::string last_segment(const std::string& uri) {
  const size_t slash = uri.find_last_of("/\\");
  return slash == std::string::npos ? uri : uri.substr(slash + 1);
}

val load_asset_js(const val& bytes_js, const std::string& name, const val& files,
                  const val& options) {
  const std::optional<io::Format> format = io::format_from_path(name);
  if (!format)
    return error_object(StatusCode::Unsupported,
                        "cannot tell the format of '" + name +
                            "': expected a .glb, .gltf, .obj, .off or .ply file");
  const std::vector<uint8_t> bytes = to_bytes(bytes_js);

  io::LoadOptions opt;
  const val weld = options.isUndefined() || options.isNull() ? val::undefined() : options["weld"];
  opt.weld.tolerance = get_number(weld, "tolerance", opt.weld.tolerance);
  opt.weld.drop_degenerate_faces = get_bool(weld, "drop_degenerate_faces", opt.weld.drop_degenerate_faces);
  opt.skip_unsupported_primitives =
      get_bool(options, "skip_unsupported_primitives", opt.skip_unsupported_primitives);

  // The resolver only looks into the object the page built from the files the user chose,
  // so it cannot reach anything else; io::load_asset_from_memory has already refused
  // absolute paths and "..".
  io::FileResolver resolver;
  if (!files.isUndefined() && !files.isNull()) {
    resolver = [&files](const std::string& uri, std::vector<uint8_t>* out) {
      for (const std::string& key : {uri, last_segment(uri)}) {
        const val f = files[key];
        if (!f.isUndefined() && !f.isNull()) {
          *out = to_bytes(f);
          return true;
        }
      }
      return false;
    };
  }

  io::LoadResult loaded = io::load_asset_from_memory(bytes, *format, name, resolver, opt);
  if (!loaded.status.ok()) return status_object(loaded.status);

  auto asset = std::make_unique<io::Asset>(std::move(loaded.asset));
  // The `meshmorph info` report (text and JSON) so the page shows what the CLI prints.
  const io::InfoReport info = io::info_report(*asset);
  const Eigen::MatrixXd normals =
      unweld(vertex_normals(asset->weld.V, asset->weld.F), asset->weld.to_welded);

  val o = status_object(Status::success());
  o.set("name", asset->source_name);
  o.set("format", std::string(io::format_name(asset->format)));
  o.set("warnings", string_array(asset->warnings));
  o.set("primitives", primitives_array(*asset));
  o.set("positions", to_float32_array(asset->V_raw));
  o.set("indices", to_uint32_array(asset->F_raw));
  o.set("normals", to_float32_array(normals));
  o.set("toWelded", to_uint32_array(asset->weld.to_welded));
  o.set("weldedVertices", static_cast<double>(asset->weld.V.rows()));
  o.set("weldedFaces", static_cast<double>(asset->weld.F.rows()));
  o.set("report", report_object(info.welded));
  o.set("text", info.text);
  o.set("info", val::global("JSON").call<val>("parse", info.json));

  const int id = g_next_asset_id++;
  asset_registry()[id] = std::move(asset);
  o.set("asset", id);
  return o;
}

bool dispose_asset_js(int id) { return asset_registry().erase(id) > 0; }

// The registered asset with this id, or null (the caller returns unknown_asset(id)).
const io::Asset* find_asset(int id) {
  const auto it = asset_registry().find(id);
  return it == asset_registry().end() ? nullptr : it->second.get();
}
val unknown_asset(int id) { return error_object(StatusCode::InvalidArgument, "no loaded asset with id " + std::to_string(id)); }

val asset_welded_mesh_js(int id) {
  const io::Asset* found = find_asset(id);
  if (!found) return unknown_asset(id);
  val o = status_object(Status::success());
  o.set("positions", to_float64_array(found->weld.V));
  o.set("indices", to_uint32_array(found->weld.F));
  return o;
}

val export_asset_js(int id, const val& positions, const std::string& format_name,
                    const val& options) {
  const io::Asset* found = find_asset(id);
  if (!found) return unknown_asset(id);
  const io::Asset& asset = *found;
  const std::optional<io::Format> format = parse_format(format_name.empty() ? "glb" : format_name);
  if (!format) return error_object(StatusCode::InvalidArgument, "unknown export format '" + format_name + "'");

  Eigen::MatrixXd V = asset.weld.V;
  if (!positions.isUndefined() && !positions.isNull()) {
    V = to_matrix(positions);
    if (V.rows() != asset.weld.V.rows())
      return error_object(StatusCode::InvalidArgument,
                          "export got " + std::to_string(V.rows()) + " positions for a mesh of " +
                              std::to_string(asset.weld.V.rows()) + " welded vertices");
  }
  io::SaveOptions opt;
  opt.recompute_normals = get_bool(options, "recompute_normals", opt.recompute_normals);
  std::vector<uint8_t> bytes;
  const Status s = io::save_asset_to_memory(asset, V, *format, &bytes, opt);
  if (!s.ok()) return status_object(s);
  val o = status_object(s);
  o.set("bytes", to_uint8_array(bytes));
  return o;
}

// A new mesh in place of the asset's geometry (merge and cut results), keeping its document.
val export_asset_with_mesh_js(int id, const val& positions, const val& indices, const std::string& format_name) {
  const io::Asset* found = find_asset(id);
  if (!found) return unknown_asset(id);
  const std::optional<io::Format> format = parse_format(format_name.empty() ? "glb" : format_name);
  if (!format) return error_object(StatusCode::InvalidArgument, "unknown export format '" + format_name + "'");
  std::vector<uint8_t> bytes;
  const Status s =
      io::save_asset_with_mesh_to_memory(*found, to_matrix(positions), to_index_matrix(indices), *format, &bytes);
  val o = status_object(s);
  if (s.ok()) o.set("bytes", to_uint8_array(bytes));
  return o;
}

val save_mesh_js(const std::string& format_name, const val& positions, const val& indices,
                 const val& colors) {
  const std::optional<io::Format> format = parse_format(format_name);
  if (!format) return error_object(StatusCode::InvalidArgument, "unknown format '" + format_name + "'");
  const Eigen::MatrixXd V = to_matrix(positions);
  const Eigen::MatrixXi F = to_index_matrix(indices);
  const Eigen::MatrixXd C = colors.isUndefined() || colors.isNull() ? Eigen::MatrixXd() : to_matrix(colors);
  std::vector<uint8_t> bytes;
  const Status s = io::save_mesh_to_memory(*format, V, F, &bytes, C);
  if (!s.ok()) return status_object(s);
  val o = status_object(s);
  o.set("bytes", to_uint8_array(bytes));
  return o;
}

val validate_mesh_js(const val& positions, const val& indices, const val& options) {
  ValidateOptions opt;
  opt.degenerate_area_tolerance =
      get_number(options, "degenerate_area_tolerance", opt.degenerate_area_tolerance);
  const MeshReport r = validate_mesh(to_matrix(positions), to_index_matrix(indices), opt);
  val o = status_object(Status::success());
  o.set("report", report_object(r));
  o.set("text", r.to_text());
  return o;
}

val spectral_basis_js(const val& positions, const val& indices, const val& options,
                      const val& progress) {
  const Eigen::MatrixXd V = to_matrix(positions);
  const Eigen::MatrixXi F = to_index_matrix(indices);
  // The eigensolver needs a manifold surface (as `meshmorph eigs` checks): refuse bad input
  // with the validator's message rather than letting the factorization fail obscurely.
  const Status valid = check_mesh(V, F, manifold_defects());
  if (!valid.ok()) return status_object(valid);

  SpectralBasisOptions opt;
  opt.k = get_int(options, "k", opt.k);
  opt.ncv = get_int(options, "ncv", opt.ncv);
  opt.relative_shift = get_number(options, "relative_shift", opt.relative_shift);
  opt.tolerance = get_number(options, "tolerance", opt.tolerance);
  opt.max_iterations = get_int(options, "max_iterations", opt.max_iterations);
  if (!parse_eigen_solver(get_string(options, "solver", "auto"), &opt.solver))
    return status_object(Status::error(StatusCode::InvalidArgument, "solver must be 'auto', 'block' or 'spectra'"));

  const SpectralBasis basis = spectral_basis(V, F, opt, js_progress(progress));
  if (!basis.status.ok()) return status_object(basis.status);
  val o = status_object(basis.status);
  o.set("eigenvalues", to_float64_array(basis.eigenvalues));
  // #V by k column-major = k by #V row-major: one contiguous block per basis function.
  o.set("vectors", to_float32_array(basis.vectors.transpose()));
  o.set("iterations", basis.iterations);
  o.set("operations", basis.operations);
  o.set("solver", std::string(basis.solver));
  return o;
}

}  // namespace

EMSCRIPTEN_BINDINGS(meshmorph_mesh) {
  bind<&load_asset_js>("loadAsset");
  bind<&dispose_asset_js>("disposeAsset");
  bind<&asset_welded_mesh_js>("assetWeldedMesh");
  bind<&export_asset_js>("exportAsset");
  bind<&export_asset_with_mesh_js>("exportAssetWithMesh");
  bind<&save_mesh_js>("saveMesh");
  bind<&validate_mesh_js>("validateMesh");
  bind<&spectral_basis_js>("spectralBasis");
}

}  // namespace mm::wasm
