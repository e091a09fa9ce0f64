// Retarget bench rows (paper 002): precompute (sampling, SVD, synthesis factorization) and the
// per-frame time (fit, descriptors, solve, V = Kt Wt) for CesiumMan → human_woman and
// Knight → Barbarian.
#include <fstream>
#include <sstream>

#include "bench.h"
#include "io/asset.h"
#include "app/retarget_job.h"
#include "character/animated_character.h"
#include "io/gltf_animation.h"
#include "mesh/midpoint_subdivide.h"
#include "retarget/curve_skeleton.h"
#include "retarget/joint_fitting.h"

namespace {

void bench_retarget(mm::bench::Context& ctx) {
  struct Case { const char* name; const char* src; const char* tgt; const char* joints; const char* clip; };
  const Case cases[] = {
      {"CesiumMan->human_woman", "anim/CesiumMan/CesiumMan.glb", "anim/human_woman.ply", "joints/human_woman_joints.json", ""},
      {"Knight->Barbarian", "anim/KayKit/Knight.glb", "anim/KayKit/Barbarian.glb", "", "Walking_A"},
  };
  for (const Case& c : cases) {
    const std::string sp = ctx.find_data(c.src), tp = ctx.find_data(c.tgt);
    if (sp.empty() || tp.empty()) continue;
    const mm::io::LoadResult src = mm::io::load_asset(sp), tgt = mm::io::load_asset(tp);
    if (!src.status.ok() || !tgt.status.ok()) continue;
    std::string joints;
    if (*c.joints) {
      std::ifstream in(ctx.find_data(c.joints));
      std::stringstream ss;
      ss << in.rdbuf();
      joints = ss.str();
    }
    // The default (articulated base on) and the paper's maps alone.
    for (const bool base : {true, false}) {
    mm::app::RetargetJobOptions opt;
    opt.clip = c.clip;
    opt.last_frame = ctx.quick ? 4 : 16;
    opt.harmonic.articulated_base = base;
    const std::string tag = base ? "" : ", maps alone";
    mm::app::RetargetJob session;
    mm::Status status;
    const double pre = ctx.time_ms([&] { status = session.prepare(src.asset, tgt.asset, joints, "", opt); }, ctx.quick ? 1 : 3);
    if (!status.ok()) continue;
    const int nv = static_cast<int>(session.target_rest().rows());
    ctx.add({"retarget", c.name, nv, "precompute (sampling, SVD, factor)" + tag, pre, "paper 002: ~1 s analysis", ""});
    // Source evaluation (LBS of the clip) is timed apart from the retargeting itself.
    std::vector<Eigen::MatrixXd> src_frames;
    for (int k = 0; k < session.num_frames(); ++k) src_frames.push_back(session.source_frame(k));
    const mm::HarmonicRetargeter& H = session.harmonic();
    const double all = ctx.time_ms([&] {
      for (const auto& X : src_frames) (void)H.retarget(X);
    }, ctx.quick ? 1 : 3);
    ctx.add({"retarget", c.name, nv, "per frame" + tag, all / src_frames.size(), "paper 002: ~4 s per frame",
             std::to_string(src_frames.size()) + " frames"});
    }
  }
}

// Automatic joints (issue 14): the curve skeleton alone, and a whole fit (two skeletons, axes,
// matching, placement) of CesiumMan's skeleton in human_woman, at ~7k vertices and with the
// surfaces split 1 → 4 at edge midpoints (armadillo 58k; the woman twice, 110k).
void bench_joints(mm::bench::Context& ctx) {
  const std::string wp = ctx.find_data("anim/human_woman.ply"), ap = ctx.find_data("edit/armadillo.ply"),
                    cp = ctx.find_data("anim/CesiumMan/CesiumMan.glb");
  if (wp.empty() || ap.empty() || cp.empty()) return;
  const mm::io::LoadResult woman = mm::io::load_asset(wp), arm = mm::io::load_asset(ap), cesium = mm::io::load_asset(cp);
  if (!woman.status.ok() || !arm.status.ok() || !cesium.status.ok()) return;
  const int reps = ctx.quick ? 1 : 3;
  const mm::Mesh w{woman.asset.V_raw, woman.asset.F_raw};
  const mm::Mesh a = mm::midpoint_subdivide(mm::Mesh{arm.asset.V_raw, arm.asset.F_raw});
  for (const auto& item : {std::pair<const char*, const mm::Mesh*>{"human_woman", &w}, {"armadillo split 1→4", &a}}) {
    const char* name = item.first;
    const mm::Mesh* m = item.second;  // not a structured binding: lambdas capture it (C++17)
    mm::Status st;
    const double ms = ctx.time_ms([&] { st = mm::curve_skeleton(m->V, m->F).status; }, reps);
    if (st.ok()) ctx.add({"joints", name, static_cast<int>(m->V.rows()), "curve skeleton", ms, "issue 14: fit ≤ 1 s at 50k", ""});
  }
  mm::io::CharacterResult c = mm::io::animated_character(cesium.asset, {});
  if (!c.status.ok()) return;
  const mm::JointSet joints = mm::character_joints(c.character);
  const mm::Mesh w4 = mm::midpoint_subdivide(mm::midpoint_subdivide(w));
  for (const auto& item : {std::pair<const char*, const mm::Mesh*>{"CesiumMan->human_woman", &w},
                           {"CesiumMan->human_woman split 1→16", &w4}}) {
    const char* name = item.first;
    const mm::Mesh* m = item.second;
    mm::Status st;
    const double ms = ctx.time_ms([&] { st = mm::fit_joints(c.character.V_rest, c.character.F, joints, m->V, m->F).status; }, reps);
    if (st.ok()) ctx.add({"joints", name, static_cast<int>(m->V.rows()), "fit (both skeletons, match, place)", ms, "issue 14: ≤ 1 s at 50k", ""});
  }
}

}  // namespace

MM_BENCH(retarget, bench_retarget);
MM_BENCH(joints, bench_joints);
