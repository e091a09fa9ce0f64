// Bindings of the retarget module (paper 002) for the page's worker (web/src/ops/retarget.js).
// Data conversion only: all work is app::RetargetJob (app/retarget_job.h).
//
// JS API:
//   retargetPrepare(sourceBytes: Uint8Array, sourceName, targetBytes: Uint8Array, targetName,
//                   targetJointsJson: string ("" = the target's skin), jointMapJson: string,
//                   options?, progress?) → {ok, session: number, frames, times: Float64Array,
//                   clip, targetPositions: Float32Array (#V·3 rest surface), targetIndices:
//                   Uint32Array, warnings: string[]}
//     options: any option of the retarget job's schema (app/retarget_job.h; optionSchema("retarget"))
//   retargetFrames(session, first, count, progress?) → {ok, positions: Float32Array
//                   (count·#V·3, frame-major), boneLengthError: number[] (per frame, mean relative;
//                   NaN for LBS), selfIntersections: number[] (per frame, triangle pairs beyond the
//                   rest pose's)}; progress returning false cancels (Cancelled)
//   retargetExportGlb(session, positions: Float32Array|Float64Array (all frames, frame-major))
//                   → {ok, bytes: Uint8Array}
//   retargetDispose(session) → boolean
//   retargetGraph(session) → {ok, sets: [{name, positions: Float32Array (#P·3), lines: Uint32Array
//                   (#L·2, empty = points), color: [r, g, b, a]}]}: the context graph (source nodes,
//                   edges and parts in source units; target nodes, edges and volume graph in target
//                   units); empty unless harmonic with context_graph on
//   retargetJoints(sourceBytes, sourceName, targetBytes, targetName, markersJson: string ("" = none),
//                  options?, progress?) → {ok, json: string ({"name": [x,y,z]}, for retargetPrepare's
//                  targetJointsJson), names: string[], positions: Float32Array (#J·3, target
//                  coordinates), parents: number[] (-1 roots), skipped: string[], warnings: string[],
//                  skeletonPositions: Float32Array (#N·3 target curve skeleton), skeletonParents:
//                  number[], targetUp: number, limbEnds: number (matched)}
//     options: any option of the joints job's schema (app/joints_job.h; optionSchema("joints"))
#include <map>
#include <memory>
#include <string>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "convert.h"
#include "io/asset.h"
#include "io/debug_lines_glb.h"
#include "app/joints_job.h"
#include "app/retarget_job.h"
#include "guard.h"

namespace mm::wasm {
namespace {

struct RetargetSlot {
  std::unique_ptr<app::RetargetJob> session;
};
std::map<int, RetargetSlot>& retarget_sessions() {
  static std::map<int, RetargetSlot> s;
  return s;
}
int g_next_retarget = 1;

io::LoadResult load_bytes(const emscripten::val& bytes, const std::string& name) {
  const auto fmt = io::format_from_path(name);
  if (!fmt) {
    io::LoadResult r;
    r.status = Status::error(StatusCode::InvalidArgument, "unknown file type: " + name);
    return r;
  }
  return io::load_asset_from_memory(to_bytes(bytes), *fmt, name);
}

emscripten::val retarget_prepare(emscripten::val src, std::string src_name, emscripten::val tgt, std::string tgt_name,
                                 std::string joints, std::string map, emscripten::val options, emscripten::val progress) {
  const io::LoadResult s = load_bytes(src, src_name);
  if (!s.status.ok()) return status_object(s.status);
  const io::LoadResult t = load_bytes(tgt, tgt_name);
  if (!t.status.ok()) return status_object(t.status);
  app::RetargetJobOptions o;
  if (Status os = read_options(options, app::retarget_options(), &o); !os.ok()) return status_object(os);
  auto session = std::make_unique<app::RetargetJob>();
  const Status st = session->prepare(s.asset, t.asset, joints, map, o, js_progress(progress));
  if (!st.ok()) return status_object(st);
  emscripten::val out = status_object(st);
  const int id = g_next_retarget++;
  out.set("session", id);
  out.set("frames", session->num_frames());
  out.set("clip", session->clip_name());
  Eigen::MatrixXd times(session->num_frames(), 1);
  for (int k = 0; k < session->num_frames(); ++k) times(k, 0) = session->times()[k];
  out.set("times", to_float64_array(times));
  out.set("targetPositions", to_float32_array(session->target_rest()));
  out.set("targetIndices", to_uint32_array(session->target_faces()));
  emscripten::val warnings = emscripten::val::array();
  for (const auto& w : session->warnings()) warnings.call<void>("push", w);
  out.set("warnings", warnings);
  retarget_sessions()[id].session = std::move(session);
  return out;
}

emscripten::val retarget_frames(int id, int first, int count, emscripten::val progress) {
  auto it = retarget_sessions().find(id);
  if (it == retarget_sessions().end())
    return status_object(Status::error(StatusCode::InvalidArgument, "unknown retarget session"));
  std::vector<Eigen::MatrixXd> frames;
  app::RetargetJob::FrameChecks checks;
  const Status st = it->second.session->frames(first, count, &frames, js_progress(progress), &checks);
  if (!st.ok()) return status_object(st);
  const int nv = static_cast<int>(it->second.session->target_rest().rows());
  Eigen::MatrixXd all(static_cast<Eigen::Index>(frames.size()) * nv, 3);
  for (size_t k = 0; k < frames.size(); ++k) all.middleRows(static_cast<Eigen::Index>(k) * nv, nv) = frames[k];
  emscripten::val out = status_object(st);
  out.set("positions", to_float32_array(all));
  out.set("count", static_cast<int>(frames.size()));
  emscripten::val bone = emscripten::val::array(), inter = emscripten::val::array();
  for (double e : checks.bone_length_error) bone.call<void>("push", e);
  for (int c : checks.self_intersections) inter.call<void>("push", c);
  out.set("boneLengthError", bone);
  out.set("selfIntersections", inter);
  return out;
}

emscripten::val retarget_export_glb(int id, emscripten::val positions) {
  auto it = retarget_sessions().find(id);
  if (it == retarget_sessions().end())
    return status_object(Status::error(StatusCode::InvalidArgument, "unknown retarget session"));
  const app::RetargetJob& s = *it->second.session;
  const Eigen::MatrixXd all = to_matrix(positions, 3);
  const int nv = static_cast<int>(s.target_rest().rows());
  if (nv == 0 || all.rows() % nv != 0 || all.rows() / nv > s.num_frames())
    return status_object(Status::error(StatusCode::InvalidArgument, "positions must hold whole frames of the target"));
  std::vector<Eigen::MatrixXd> frames;
  for (int k = 0; k < all.rows() / nv; ++k) frames.push_back(all.middleRows(static_cast<Eigen::Index>(k) * nv, nv));
  std::vector<double> times(s.times().begin(), s.times().begin() + frames.size());
  std::vector<uint8_t> bytes;
  const Status st = s.write_glb(frames, times, &bytes);
  if (!st.ok()) return status_object(st);
  emscripten::val out = status_object(st);
  out.set("bytes", to_uint8_array(bytes));
  return out;
}

// The session's context graph as overlay sets (RetargetJob::context_graph_overlay): empty
// unless the harmonic method runs with context_graph on.
emscripten::val retarget_graph(int id) {
  auto it = retarget_sessions().find(id);
  if (it == retarget_sessions().end())
    return status_object(Status::error(StatusCode::InvalidArgument, "unknown retarget session"));
  emscripten::val out = status_object(Status::success());
  emscripten::val sets = emscripten::val::array();
  for (const io::DebugGeometry& d : it->second.session->context_graph_overlay()) {
    emscripten::val o = emscripten::val::object();
    o.set("name", d.name);
    o.set("positions", to_float32_array(d.P));
    Eigen::MatrixXi L(static_cast<Eigen::Index>(d.lines.size()), 2);
    for (size_t k = 0; k < d.lines.size(); ++k) L.row(static_cast<Eigen::Index>(k)) << d.lines[k].first, d.lines[k].second;
    o.set("lines", to_uint32_array(L));
    emscripten::val c = emscripten::val::array();
    for (float x : d.color) c.call<void>("push", x);
    o.set("color", c);
    sets.call<void>("push", o);
  }
  out.set("sets", sets);
  return out;
}

bool retarget_dispose(int id) { return retarget_sessions().erase(id) > 0; }

emscripten::val retarget_joints(emscripten::val src, std::string src_name, emscripten::val tgt, std::string tgt_name,
                                std::string markers, emscripten::val options, emscripten::val progress) {
  const io::LoadResult s = load_bytes(src, src_name);
  if (!s.status.ok()) return status_object(s.status);
  const io::LoadResult t = load_bytes(tgt, tgt_name);
  if (!t.status.ok()) return status_object(t.status);
  app::JointsJobOptions o;
  if (Status os = read_options(options, app::joints_options(), &o); !os.ok()) return status_object(os);
  const app::JointsJobResult r = app::run_joints_job(s.asset, t.asset, markers, o, js_progress(progress));
  if (!r.status.ok()) return status_object(r.status);
  emscripten::val out = status_object(r.status);
  auto strings = [](const std::vector<std::string>& v) {
    emscripten::val a = emscripten::val::array();
    for (const auto& x : v) a.call<void>("push", x);
    return a;
  };
  auto ints = [](const std::vector<int>& v) {
    emscripten::val a = emscripten::val::array();
    for (int x : v) a.call<void>("push", x);
    return a;
  };
  out.set("json", r.json);
  out.set("names", strings(r.fit.joints.names));
  out.set("positions", to_float32_array(r.fit.joints.P));
  out.set("parents", ints(r.fit.joints.parent));
  out.set("skipped", strings(r.fit.skipped));
  out.set("warnings", strings(r.warnings));
  out.set("skeletonPositions", to_float32_array(r.fit.target_skeleton.nodes));
  out.set("skeletonParents", ints(r.fit.target_skeleton.parent));
  out.set("targetUp", r.fit.target_up);
  out.set("limbEnds", static_cast<int>(r.fit.limb_ends.size()));
  return out;
}

}  // namespace
}  // namespace mm::wasm

EMSCRIPTEN_BINDINGS(meshmorph_retarget) {
  using namespace mm::wasm;
  bind<&retarget_prepare>("retargetPrepare");
  bind<&retarget_frames>("retargetFrames");
  bind<&retarget_export_glb>("retargetExportGlb");
  bind<&retarget_dispose>("retargetDispose");
  bind<&retarget_joints>("retargetJoints");
  bind<&retarget_graph>("retargetGraph");
}
