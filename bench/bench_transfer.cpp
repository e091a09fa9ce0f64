// Pose-transfer stages (issue 4) for the largest pair in data/: TOSCA horse0 (19,248 v) as the
// reference, Sumner camel_ref (21,887 v) as the source, with data/landmarks/horse0-camel_ref.json.
// Peer: paper 000 Table 1, Fig. 1 pair (19,248 / 10,889 v, cage 452; Core i7-3520M):
// bases + MVC 122.1 s, optimisation 31.5 s (10 iterations). --quick uses cat-01 → lion.
#include <algorithm>
#include <cstdio>

#include "bench.h"
#include "io/asset.h"
#include "io/landmarks_file.h"
#include "metrics/transfer_metrics.h"
#include "transfer/part_transfer.h"
#include "transfer/pose_transfer.h"

namespace mm::bench {
namespace {

std::vector<LandmarkPair> bench_transfer_pairs(const std::string& path) {
  std::vector<LandmarkPair> out;
  if (!io::read_landmarks(path, &out).ok()) out.clear();
  return out;
}


// PoseTransferOptions::fold_retry_resolution: what the default run did, and the same transfer
// without the fold check (the figure earlier bench tables had).
std::string fold_retry_note(const PoseTransferResult& r) {
  if (!r.fold_retry.tried) return "";
  return std::string("includes the fold retry (cage on ") + std::to_string(r.fold_retry.resolution) + " cells, " +
         (r.fold_retry.kept ? "kept" : "not kept") + ", " + std::to_string(static_cast<int>(r.fold_retry.ms)) + " ms)";
}

void add_fold_rows(Context& ctx, const std::string& mesh, int nv, const Mesh& R, const Mesh& S,
                   const std::vector<LandmarkPair>& pairs, const PoseTransferResult& r) {
  if (!r.fold_retry.tried) return;
  PoseTransferOptions off;
  off.fold_retry_resolution = 0;
  const PoseTransferResult plain = pose_transfer(R, S, pairs, off);
  if (!plain.status.ok()) return;
  ctx.add({"transfer", mesh, nv, "whole transfer, no fold check", plain.ms.total, "",
           "first result: " + std::to_string(r.fold_retry.first.flipped_faces) + " flipped faces, " +
               std::to_string(r.fold_retry.first.self_intersections_result) + " self-intersecting pairs (inputs " +
               std::to_string(r.fold_retry.first.self_intersections_reference + r.fold_retry.first.self_intersections_source) +
               ")"});
}

void transfer_suite(Context& ctx) {
  const std::string ref_rel = ctx.quick ? "pose/cat-01.ply" : "pose/horse0.ply";
  const std::string src_rel = ctx.quick ? "pose/lion-reference.ply" : "pose/camel_ref.ply";
  const std::string lm_rel = ctx.quick ? "landmarks/cat-lion.json" : "landmarks/horse0-camel_ref.json";
  const std::string ref_path = ctx.find_data(ref_rel), src_path = ctx.find_data(src_rel), lm_path = ctx.find_data(lm_rel);
  if (ref_path.empty() || src_path.empty() || lm_path.empty()) {
    std::fprintf(stderr, "  transfer: data missing, skipped\n");
    return;
  }
  const io::LoadResult ref = io::load_asset(ref_path), src = io::load_asset(src_path);
  if (!ref.status.ok() || !src.status.ok()) return;
  const Mesh R = ref.asset.mesh(), S = src.asset.mesh();
  const auto pairs = bench_transfer_pairs(lm_path);
  PoseTransferResult best;
  const int repeats = ctx.quick ? 1 : 3;
  std::vector<PoseTransferResult> runs;
  for (int i = 0; i < repeats; ++i) runs.push_back(pose_transfer(R, S, pairs));
  if (!runs[0].status.ok()) {
    std::fprintf(stderr, "  transfer: %s\n", runs[0].status.message.c_str());
    return;
  }
  auto median = [&](double PoseTransferTimings::*f) {
    std::vector<double> v;
    for (const auto& r : runs) v.push_back(r.ms.*f);
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  const PoseTransferResult& r = runs[0];
  const std::string mesh = S.num_vertices() > 20000 ? "horse0->camel_ref" : "cat-01->lion";
  const int nv = S.num_vertices();
  const bool big = !ctx.quick;
  ctx.add({"transfer", mesh, nv, "eigenbases (2 meshes, k'=20)", median(&PoseTransferTimings::eigenbases), "", ""});
  ctx.add({"transfer", mesh, nv, "coupled bases", median(&PoseTransferTimings::coupling), "",
           std::to_string(r.coupling_iterations) + " steps, Γ dominance " + std::to_string(r.gamma_dominance).substr(0, 5)});
  ctx.add({"transfer", mesh, nv, "cage", median(&PoseTransferTimings::cage), "",
           std::to_string(r.cage_rest.rows()) + " cage vertices"});
  ctx.add({"transfer", mesh, nv, "mean-value coordinates", median(&PoseTransferTimings::mvc), "", ""});
  ctx.add({"transfer", mesh, nv, "bases + cage + MVC",
           median(&PoseTransferTimings::eigenbases) + median(&PoseTransferTimings::coupling) +
               median(&PoseTransferTimings::cage) + median(&PoseTransferTimings::mvc),
           big ? "paper 000: 122.1 s (bases + MVC)" : "", ""});
  ctx.add({"transfer", mesh, nv, "optimisation", median(&PoseTransferTimings::optimisation),
           big ? "paper 000: 31.5 s (10 it)" : "", std::to_string(r.iterations) + " iterations"});
  ctx.add({"transfer", mesh, nv, "whole transfer", median(&PoseTransferTimings::total),
           big ? "paper 000: 153.6 s; aim <= 3 s" : "", fold_retry_note(r)});
  add_fold_rows(ctx, mesh, nv, R, S, pairs, r);
}

// Paper 000 Fig. 10 pair: TOSCA michael9 (52,565 v, 3 holes) as the reference, the armadillo
// (14,587 v) as the source, with data/landmarks/michael3-armadillo.json (michael3 indices = michael9
// indices). michael is not bundled: read from ../shared/data when present, skipped otherwise and
// in --quick runs (the 52k-vertex eigenbasis alone takes seconds).
void transfer_michael_armadillo(Context& ctx) {
  if (ctx.quick) return;
  const std::string ref_path = ctx.find_data("", "pose/tosca/michael9.off");
  const std::string src_path = ctx.find_data("edit/armadillo.ply");
  const std::string lm_path = ctx.find_data("landmarks/michael3-armadillo.json");
  if (ref_path.empty() || src_path.empty() || lm_path.empty()) {
    std::fprintf(stderr, "  transfer: michael9 (../shared/data) missing, michael9->armadillo skipped\n");
    return;
  }
  const io::LoadResult ref = io::load_asset(ref_path), src = io::load_asset(src_path);
  if (!ref.status.ok() || !src.status.ok()) return;
  const Mesh R = ref.asset.mesh(), S = src.asset.mesh();
  const auto pairs = bench_transfer_pairs(lm_path);
  const PoseTransferResult r = pose_transfer(R, S, pairs);  // one run, ~7 s (+6 s fold retry)
  if (!r.status.ok()) {
    std::fprintf(stderr, "  transfer: michael9->armadillo: %s\n", r.status.message.c_str());
    return;
  }
  const std::string mesh = "michael9->armadillo";
  const int nv = S.num_vertices();
  // Peer: paper 000 Table 1, Fig. 10 row — a 10,002 v man and a 10,495 v armadillo, cage 502.
  ctx.add({"transfer", mesh, nv, "bases + cage + MVC", r.ms.eigenbases + r.ms.coupling + r.ms.cage + r.ms.mvc,
           "paper 000: 55.5 s (10.0k/10.5k v)",
           "reference 52,565 v; Γ dominance " + std::to_string(r.gamma_dominance).substr(0, 5) + ", " +
               std::to_string(r.cage_rest.rows()) + " cage vertices"});
  ctx.add({"transfer", mesh, nv, "optimisation", r.ms.optimisation, "paper 000: 173.5 s",
           std::to_string(r.iterations) + " iterations"});
  const TransferMetrics m = transfer_metrics(r.V, S.V, S.F);  // against the source: detail kept, fold-overs
  ctx.add({"transfer", mesh, nv, "whole transfer", r.ms.total, "paper 000: 229.0 s",
           std::to_string(m.flipped_faces) + " flipped faces, detail " + std::to_string(m.laplacian_change).substr(0, 5) +
               (r.fold_retry.tried ? "; " + fold_retry_note(r) : "")});
  add_fold_rows(ctx, mesh, nv, R, S, pairs, r);
}

// Two levels (issue 16): cat-05 -> cat-reference with automatic parts (three rounds of three
// candidate sets, run side by side on the pool since the twenty-fourth session). One run (~30-60 s
// natively); not in --quick runs.
void transfer_parts(Context& ctx) {
  if (ctx.quick) return;
  const std::string ref_path = ctx.find_data("pose/cat-05.ply"), src_path = ctx.find_data("pose/cat-reference.ply");
  if (ref_path.empty() || src_path.empty()) return;
  const io::LoadResult ref = io::load_asset(ref_path), src = io::load_asset(src_path);
  if (!ref.status.ok() || !src.status.ok()) return;
  const Mesh R = ref.asset.mesh(), S = src.asset.mesh();
  const PartTransferResult r = part_transfer(R, S, {}, nullptr);
  if (!r.status.ok()) {
    std::fprintf(stderr, "  transfer: cat-05 parts: %s\n", r.status.message.c_str());
    return;
  }
  int kept = 0;
  for (const PartReport& p : r.reports) kept += p.status.ok();
  ctx.add({"transfer", "cat-05->cat-reference", S.num_vertices(), "automatic parts (after level 1)", r.ms_parts, "",
           std::to_string(r.proposals_tried) + " candidate sets in " + std::to_string(r.proposal_rounds) + " rounds, " +
               std::to_string(kept) + " parts kept; level 1 " + std::to_string(static_cast<int>(r.ms_level1)) + " ms"});
}

void transfer_suites(Context& ctx) {
  transfer_suite(ctx);
  transfer_michael_armadillo(ctx);
  transfer_parts(ctx);
}

}  // namespace
}  // namespace mm::bench

MM_BENCH(transfer, mm::bench::transfer_suites);
