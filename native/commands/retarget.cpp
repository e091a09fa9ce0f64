// meshmorph retarget: animate a target character with a source character's clip (paper 002).
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli.h"
#include "io/asset.h"
#include "app/joints_job.h"
#include "app/retarget_job.h"
#include "io/debug_lines_glb.h"
#include "metrics/retarget_metrics.h"

namespace {

const char* kRetargetUsage = R"(usage: meshmorph retarget --source SRC.glb --target TGT --out OUT.glb [--target-joints J.json]
                          [--joint-map M.json] [--frames a:b] [options]

Animates TGT (glTF/GLB with or without a skin, or OBJ/OFF/PLY) with a clip of the skinned,
animated SRC, without rigging TGT (harmonic maps, paper 002). OUT.glb holds the target with
morph targets and an animation of their weights (plays in three.js and Blender): one target per
frame (--export frames), or the clip's mean and K principal components with K weights per frame
(--export compact; the default for more than 60 frames: K is the smallest that keeps every vertex
within --export-tolerance × the target's size). An OUT with .obj/.ply/.off writes one mesh file
per frame (OUT_0000.obj, ...).

  --target-joints J.json   {"joint name": [x, y, z], ...} with the source's joint names
                           (needed when TGT has no skin); "auto" fits the source's joints
                           inside TGT (as `meshmorph joints`, default options)
  --markers M.json         with --target-joints auto: {"joint name": [x, y, z]} pins these
                           joints of the fit (chin, wrists, elbows, knees, groin, ...)
  --joint-map M.json       {"source joint": "target joint", ...} where names differ
  --frames a:b             shorthand for --first-frame a --last-frame b (either side optional)
  --debug-graph OUT.glb    with --context-graph on: the context graph (source nodes, edges and body
                           parts; compatible target nodes and edges; the target's volume graph) as
                           glTF line and point sets
options (app/retarget_job.h):
)";

// A JSON input file (joints, joint map) through io::read_file (regular files only, size-limited).
mm::Status read_text(const std::string& path, std::string* out) {
  std::vector<uint8_t> bytes;
  mm::Status s = mm::io::read_file(path, &bytes);
  if (s.ok()) out->assign(bytes.begin(), bytes.end());
  return s;
}

int run_retarget(const std::vector<std::string>& argv) {
  using namespace mm;
  cli::Args args;
  Status s = args.parse(argv, {"help"});
  if (!s.ok()) return cli::report("retarget", s);
  if (args.has("help")) {
    std::cout << kRetargetUsage << app::retarget_options().help();
    return 0;
  }
  const std::string src_path = args.get("source"), tgt_path = args.get("target"), out_path = args.get("out");
  if (src_path.empty() || tgt_path.empty() || out_path.empty())
    return cli::report("retarget", Status::error(StatusCode::InvalidArgument, "--source, --target and --out are required (see --help)"));
  const auto& schema = app::retarget_options();
  app::RetargetJobOptions opt;
  if (!(s = cli::read_options(args, schema, &opt)).ok()) return cli::report("retarget", s);
  if (args.has("frames")) {
    const std::string r = args.get("frames");
    const auto colon = r.find(':');
    const std::string a = colon == std::string::npos ? "" : r.substr(0, colon);
    const std::string b = colon == std::string::npos ? "" : r.substr(colon + 1);
    Status fs = colon == std::string::npos ? Status::error(StatusCode::InvalidArgument, "--frames expects a:b, e.g. 0:30")
                                           : Status::success();
    if (fs.ok() && !a.empty()) fs = schema.set(opt, "first_frame", app::OptionValue::of_text(a));
    if (fs.ok() && !b.empty()) fs = schema.set(opt, "last_frame", app::OptionValue::of_text(b));
    if (!fs.ok()) return cli::report("retarget", Status::error(fs.code, "--frames: " + fs.message));
  }
  std::string joints_json, map_json;
  if (args.has("target-joints") && args.get("target-joints") == "auto") joints_json = "auto";
  else if (args.has("target-joints") && !(s = read_text(args.get("target-joints"), &joints_json)).ok())
    return cli::report("retarget", s);
  if (args.has("joint-map") && !(s = read_text(args.get("joint-map"), &map_json)).ok()) return cli::report("retarget", s);
  std::string markers_json;
  if (args.has("markers")) {
    if (joints_json != "auto")
      return cli::report("retarget", Status::error(StatusCode::InvalidArgument,
                                                   "--markers pins the automatic joints: give it with --target-joints auto"));
    if (!(s = read_text(args.get("markers"), &markers_json)).ok()) return cli::report("retarget", s);
  }
  const std::string graph_path = args.has("debug-graph") ? args.get("debug-graph") : "";
  if (!(s = cli::check_unused(args)).ok()) return cli::report("retarget", s);
  if (!graph_path.empty() && !(opt.method == app::RetargetMethod::Harmonic && opt.harmonic.context_graph))
    return cli::report("retarget", Status::error(StatusCode::InvalidArgument,
                                                 "--debug-graph needs the harmonic method with --context-graph on"));
  if (!graph_path.empty() && !(s = io::check_output_path(graph_path)).ok()) return cli::report("retarget", s);

  if (!(s = io::check_output_path(out_path)).ok()) return cli::report("retarget", s);
  io::LoadResult src = io::load_asset(src_path);
  if (!src.status.ok()) return cli::report("retarget", src.status);
  io::LoadResult tgt = io::load_asset(tgt_path);
  if (!tgt.status.ok()) return cli::report("retarget", tgt.status);
  const Progress progress = cli::terminal_progress();
  app::RetargetJob session;
  const auto t0 = std::chrono::steady_clock::now();
  if (!markers_json.empty()) {
    // The pinned fit is the joints job's (as the page does): its JSON is the target's joints.
    const app::JointsJobResult fit = app::run_joints_job(src.asset, tgt.asset, markers_json, {}, progress.sub(0, 0.1));
    if (!fit.status.ok()) return cli::report("retarget", Status{fit.status.code, "automatic target joints: " + fit.status.message});
    for (const auto& w : fit.warnings) std::cerr << "meshmorph retarget: warning: " << w << "\n";
    joints_json = fit.json;
  }
  s = session.prepare(src.asset, tgt.asset, joints_json, map_json, opt, progress.sub(0, 0.3));
  if (!s.ok()) return cli::report("retarget", s);
  const auto t1 = std::chrono::steady_clock::now();
  for (const auto& w : session.warnings()) std::cerr << "meshmorph retarget: warning: " << w << "\n";
  if (!graph_path.empty()) {
    std::vector<uint8_t> glb;
    if (!(s = session.debug_graph_glb(&glb)).ok()) return cli::report("retarget", s);
    if (!(s = io::write_file_atomic(graph_path, glb)).ok()) return cli::report("retarget", s);
    const ContextGraphInfo& g = session.harmonic().context_graph();
    std::cout << "  context graph: " << g.source_nodes.rows() << " nodes, " << g.edges.size() << " edges ("
              << g.calibration_edges.size() << " at rest; rules removed " << g.counts.same_part << " same-part, "
              << g.counts.too_long << " long, " << g.counts.interior << " interior), volume graph "
              << g.volume_nodes.rows() << " nodes; wrote " << graph_path << "\n";
  }
  std::vector<Eigen::MatrixXd> frames;
  s = session.frames(0, session.num_frames(), &frames, progress.sub(0.3, 0.95));
  if (!s.ok()) return cli::report("retarget", s);
  const auto t2 = std::chrono::steady_clock::now();

  const std::string ext = out_path.size() > 4 ? out_path.substr(out_path.rfind('.') + 1) : "";
  std::string export_line;
  if (ext == "glb" || ext == "gltf") {
    std::vector<uint8_t> bytes;
    io::MorphAnimationReport report;
    const auto e0 = std::chrono::steady_clock::now();
    s = session.write_glb(frames, session.times(), &bytes, &report);
    if (!s.ok()) return cli::report("retarget", s);
    const double export_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - e0).count();
    if (!(s = io::write_file_atomic(out_path, bytes)).ok()) return cli::report("retarget", s);
    std::ostringstream line;
    line << "  export " << (report.compact ? "compact" : "frames") << ": " << report.targets << " morph targets";
    if (report.compact)
      line << " (mean + K = " << report.components << " components" << (report.quantized ? ", SHORT" : ", FLOAT")
           << "), max error " << report.max_error << " of the size (tolerance " << opt.export_tolerance << ")";
    line << ", " << bytes.size() / 1e6 << " MB, " << static_cast<int>(export_ms) << " ms\n";
    if (report.capped)
      line << "  warning: the tolerance is not met with " << report.components
           << " components (--export-max-components); the file is within " << report.max_error << " of the size\n";
    export_line = line.str();
  } else {
    const std::string stem = out_path.substr(0, out_path.rfind('.'));
    for (size_t k = 0; k < frames.size(); ++k) {
      char name[32];
      std::snprintf(name, sizeof name, "_%04zu.", k);
      s = io::save_mesh(stem + name + ext, frames[k], session.target_faces());
      if (!s.ok()) return cli::report("retarget", s);
    }
  }
  const double pre_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  const double frame_ms = std::chrono::duration<double, std::milli>(t2 - t1).count() / std::max<size_t>(1, frames.size());
  std::cout << "retarget: clip '" << session.clip_name() << "', " << frames.size() << " frames, method " << (opt.method == app::RetargetMethod::Lbs ? "lbs" : "harmonic")
            << "; precompute " << static_cast<int>(pre_ms) << " ms, " << frame_ms << " ms per frame\n";
  if (opt.method == app::RetargetMethod::Harmonic) {
    const auto& H = session.harmonic();
    std::vector<Eigen::MatrixXd> joints;
    for (int k = 0; k < session.num_frames(); ++k) joints.push_back(H.retarget(session.source_frame(k)).joints);
    const BoneLengthError be = bone_length_error(joints, H.bones(), H.rest_bone_lengths());
    std::cout << "  " << H.used_joints().size() << " joints, " << H.bones().size() << " bones; bone-length error mean "
              << be.mean << ", max " << be.max << " (relative)\n";
  }
  std::cout << export_line << "  wrote " << out_path << "\n";
  return 0;
}

}  // namespace

namespace {

const char* kJointsUsage = R"(usage: meshmorph joints TARGET --like SOURCE.glb --out J.json [--markers M.json]
                       [--debug-skeleton OUT.glb] [options]

Places the joints of the skinned SOURCE inside the unrigged TARGET (glTF or OBJ/OFF/PLY):
curve skeletons of both (voxel level-set skeleton), limbs matched after aligning up and
facing, joints carried over by their proportions along each limb (retarget/joint_fitting.h).
J.json is {"joint name": [x, y, z]} in TARGET's coordinates, ready for
`meshmorph retarget --target-joints J.json`.

  --markers M.json         {"joint name": [x, y, z]}: pin these source joints (chin, wrists,
                           knees, ...) where the automatic fit is wrong
  --debug-skeleton OUT.glb the target's curve skeleton (lines), the fitted joints and bones,
                           and the target surface (translucent), for viewing; written for a
                           refused fit too (the skeleton alone)
options (app/joints_job.h):
)";

int run_joints(const std::vector<std::string>& argv) {
  using namespace mm;
  cli::Args args;
  Status s = args.parse(argv, {"help"});
  if (!s.ok()) return cli::report("joints", s);
  if (args.has("help")) {
    std::cout << kJointsUsage << app::joints_options().help();
    return 0;
  }
  const std::string src_path = args.get("like"), out_path = args.get("out"), debug_path = args.get("debug-skeleton");
  if (args.positional().size() != 1 || src_path.empty() || out_path.empty())
    return cli::report("joints", Status::error(StatusCode::InvalidArgument, "expected TARGET --like SOURCE.glb --out J.json (see --help)"));
  const std::string tgt_path = args.positional()[0];
  app::JointsJobOptions opt;
  if (!(s = cli::read_options(args, app::joints_options(), &opt)).ok()) return cli::report("joints", s);
  std::string markers_json;
  if (args.has("markers") && !(s = read_text(args.get("markers"), &markers_json)).ok()) return cli::report("joints", s);
  if (!(s = cli::check_unused(args)).ok()) return cli::report("joints", s);
  if (!(s = io::check_output_path(out_path)).ok()) return cli::report("joints", s);
  if (!debug_path.empty() && !(s = io::check_output_path(debug_path)).ok()) return cli::report("joints", s);
  io::LoadResult src = io::load_asset(src_path);
  if (!src.status.ok()) return cli::report("joints", src.status);
  io::LoadResult tgt = io::load_asset(tgt_path);
  if (!tgt.status.ok()) return cli::report("joints", tgt.status);
  const auto t0 = std::chrono::steady_clock::now();
  const app::JointsJobResult r = app::run_joints_job(src.asset, tgt.asset, markers_json, opt, cli::terminal_progress());
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& w : r.warnings) std::cerr << "meshmorph joints: warning: " << w << "\n";
  // The debug view is written for a refused fit too (the target's skeleton shows why).
  auto write_debug = [&]() -> Status {
    auto skeleton_set = [](const CurveSkeleton& sk, const Eigen::Matrix3d& to_target, const std::string& name,
                           std::array<float, 4> color) {
      io::DebugGeometry g;
      g.name = name;
      g.P = sk.nodes * to_target.transpose();
      for (int i = 0; i < sk.size(); ++i)
        if (sk.parent[i] >= 0) g.lines.push_back({i, sk.parent[i]});
      g.color = color;
      return g;
    };
    std::vector<io::DebugGeometry> sets;
    io::DebugGeometry surface;
    surface.name = "target surface";
    surface.P = r.target_V;
    surface.F = r.target_F;
    surface.color = {0.7f, 0.7f, 0.75f, 0.25f};
    sets.push_back(surface);
    sets.push_back(skeleton_set(r.fit.target_skeleton, Eigen::Matrix3d::Identity(), "target curve skeleton", {0.1f, 0.6f, 1, 1}));
    io::DebugGeometry joints, bones;
    joints.name = "fitted joints";
    joints.P = r.fit.joints.P;
    joints.color = {1, 0.2f, 0.1f, 1};
    bones.name = "fitted bones";
    bones.P = r.fit.joints.P;
    for (int j = 0; j < r.fit.joints.size(); ++j)
      if (r.fit.joints.parent[j] >= 0) bones.lines.push_back({j, r.fit.joints.parent[j]});
    bones.color = {1, 0.6f, 0.1f, 1};
    if (joints.P.rows() > 0) sets.push_back(joints);
    if (!bones.lines.empty()) sets.push_back(bones);
    std::vector<uint8_t> glb;
    if (Status st = io::debug_geometry_glb(sets, &glb); !st.ok()) return st;
    return io::write_file_atomic(debug_path, glb);
  };
  if (!r.status.ok()) {
    if (!debug_path.empty() && r.fit.target_skeleton.size() > 0 && write_debug().ok())
      std::cerr << "meshmorph joints: wrote " << debug_path << " (the target's skeleton; no joints)\n";
    return cli::report("joints", r.status);
  }
  const std::vector<uint8_t> bytes(r.json.begin(), r.json.end());
  if (!(s = io::write_file_atomic(out_path, bytes)).ok()) return cli::report("joints", s);
  if (!debug_path.empty() && !(s = write_debug()).ok()) return cli::report("joints", s);
  const auto& fit = r.fit;
  std::cout << "joints: " << fit.joints.size() << " joints placed (" << fit.skipped.size()
            << " source joints outside the source surface skipped) in " << static_cast<int>(ms) << " ms; skeletons "
            << fit.source_skeleton.size() << " / " << fit.target_skeleton.size() << " nodes, limb ends "
            << fit.source_skeleton.leaves().size() << " / " << fit.target_skeleton.leaves().size() << " ("
            << fit.limb_ends.size() << " matched), target up axis " << fit.target_up << "\n  skeleton prior "
            << std::setprecision(3);
  if (fit.skeleton_prior_used > 0)
    std::cout << "weight " << fit.skeleton_prior_used;
  else
    std::cout << "not used";
  std::cout << " (the fitted bones differ from the source's by " << fit.skeleton_agreement << ")\n";
  if (fit.middle_moved > 0) std::cout << "  " << fit.middle_moved << " middle joints moved sideways to the middle of the target's body\n";
  if (fit.depth_moved > 0) std::cout << "  " << fit.depth_moved << " joints moved to the source's fraction of their limb's depth\n";
  if (fit.mirrored > 0) std::cout << "  " << fit.mirrored << " joints made mirror images of their partners (a symmetric target)\n";
  std::cout << "  wrote " << out_path << "\n";
  if (!debug_path.empty()) std::cout << "  wrote " << debug_path << "\n";
  return 0;
}

}  // namespace

MM_COMMAND(joints, "automatic joints: fit a source character's skeleton inside an unrigged target", run_joints);


MM_COMMAND(retarget, "animate a target mesh with a source character's clip (harmonic maps, paper 002)", run_retarget);
