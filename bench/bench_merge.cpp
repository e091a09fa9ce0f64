// Merge stages (paper 001 Sec. 5, 6): the camel's head onto the horse's neck (the test case of
// tests/merge_test.cpp), at the repo's size (11.4k source vertices, like the paper's 16k
// Mannequin head) and with the source midpoint-subdivided once (45k source vertices, ≥ 50k in
// the merged mesh). Rows: precompute (editor on the whole source), solve (Eq. 7 + finalize),
// zip (band removal, gap triangulation, smoothing), total. Peer: paper 001 Table 1.
#include <cstdio>
#include <map>

#include "bench.h"
#include "io/asset.h"
#include "merge/cut.h"
#include "merge/mesh_merge.h"
#include "mesh/midpoint_subdivide.h"
#include "mesh/topology.h"

namespace mm::bench {
namespace {


int merge_bench_extreme(const Eigen::MatrixXd& V, const std::vector<int>& loop, int axis, bool largest) {
  int best = loop[0];
  for (int v : loop)
    if (largest ? V(v, axis) > V(best, axis) : V(v, axis) < V(best, axis)) best = v;
  return best;
}

void merge_suite(Context& ctx) {
  const std::string horse_path = ctx.find_data("pose/horse0.ply"), head_path = ctx.find_data("edit/camelhead.ply");
  if (horse_path.empty() || head_path.empty()) return;
  const io::LoadResult horse = io::load_asset(horse_path), head = io::load_asset(head_path);
  if (!horse.status.ok() || !head.status.ok()) return;
  const Mesh h = horse.asset.mesh();
  const CutResult body = cut_plane(h.V, h.F, {0, -85, 140}, Eigen::Vector3d(0, -1, 1), {0, 0, 100});
  if (!body.status.ok()) return;
  for (int level = 0; level < (ctx.quick ? 1 : 2); ++level) {
    Mesh src = head.asset.mesh();
    for (int k = 0; k < level; ++k) src = midpoint_subdivide(src);
    MergeInput in;
    in.target_V = body.V;
    in.target_F = body.F;
    in.source_V = src.V;
    in.source_F = src.F;
    const auto tl = boundary_loops(body.F, static_cast<int>(body.V.rows()));
    const auto sl = boundary_loops(src.F, src.num_vertices());
    MergeBoundaryPair p;
    p.target_keys = {merge_bench_extreme(body.V, tl[0], 2, true), merge_bench_extreme(body.V, tl[0], 2, false)};
    p.source_keys = {merge_bench_extreme(src.V, sl[0], 1, true), merge_bench_extreme(src.V, sl[0], 1, false)};
    in.pairs = {p};
    MergeResult r;
    const double total = ctx.time_ms([&] { r = merge_meshes(in); }, ctx.quick ? 1 : 2);
    if (!r.status.ok()) {
      std::fprintf(stderr, "  merge: %s\n", r.status.message.c_str());
      continue;
    }
    const std::string name = level == 0 ? "camelhead→horse" : "camelhead×4→horse";
    const int n = static_cast<int>(r.V.rows());
    const std::string setup = std::to_string(r.stats.source_vertices) + " source, " +
                              std::to_string(r.stats.boundary_constraints) + " constraints";
    const bool paper = level == 0;
    ctx.add({"merge", name, n, "precompute (editor on the source)", r.stats.precompute_ms,
             paper ? "paper 001 (16k head): 1.437 + 0.234 s" : "", setup});
    ctx.add({"merge", name, n, "solve (Eq. 7 + finalize)", r.stats.solve_ms,
             paper ? "paper 001: 0.062 + 0.328 + 0.032 s" : "", ""});
    ctx.add({"merge", name, n, "zip (band, gap, smoothing)", r.stats.zip_ms, "", ""});
    ctx.add({"merge", name, n, "total", total, "", "aim: < 1 s at 50k natively"});
  }
}

}  // namespace

MM_BENCH(merge, merge_suite);

}  // namespace mm::bench
