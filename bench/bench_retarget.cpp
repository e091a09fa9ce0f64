// Retarget bench rows (paper 002): precompute (sampling, SVD, synthesis factorization) and the
// per-frame time (fit, descriptors, solve, V = Kt Wt) for CesiumMan → human_woman and
// Knight → Barbarian.
#include <fstream>
#include <sstream>

#include "bench.h"
#include "io/asset.h"
#include "app/retarget_job.h"

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
    mm::app::RetargetJobOptions opt;
    opt.clip = c.clip;
    opt.last_frame = ctx.quick ? 4 : 16;
    mm::app::RetargetJob session;
    mm::Status status;
    const double pre = ctx.time_ms([&] { status = session.prepare(src.asset, tgt.asset, joints, "", opt); }, ctx.quick ? 1 : 3);
    if (!status.ok()) continue;
    const int nv = static_cast<int>(session.target_rest().rows());
    ctx.add({"retarget", c.name, nv, "precompute (sampling, SVD, factor)", pre, "paper 002: ~1 s analysis", ""});
    // Source evaluation (LBS of the clip) is timed apart from the retargeting itself.
    std::vector<Eigen::MatrixXd> src_frames;
    for (int k = 0; k < session.num_frames(); ++k) src_frames.push_back(session.source_frame(k));
    const mm::HarmonicRetargeter& H = session.harmonic();
    const double all = ctx.time_ms([&] {
      for (const auto& X : src_frames) (void)H.retarget(X);
    }, ctx.quick ? 1 : 3);
    ctx.add({"retarget", c.name, nv, "per frame", all / src_frames.size(), "paper 002: ~4 s per frame",
             std::to_string(src_frames.size()) + " frames"});
  }
}

}  // namespace

MM_BENCH(retarget, bench_retarget);
