// The merge job (paper 001 Sec. 5, 6) and the cut job that prepares its inputs: options schema,
// the JSON merge spec, and the whole jobs on files (load → merge/cut → save keeping the target's
// document) for the CLI, the wasm module and the bench.
//
// Merge spec (vertex indices are those of the welded meshes, as `meshmorph info` and the page
// show them):
//   {
//     "pairs": [ { "target_keys": [t0, t1, ...], "source_keys": [s0, s1, ...],   ≥ 2 each, same count
//                  "target_loop": i, "source_loop": j } ],    loops optional (default: the keys' loop)
//     "fixed": [source vertex, ...],        configuration-dependent mode: source handles kept in place
//     "options": { "mode": "dependent", "roi_width": 0.2, ... }   any option of `meshmorph options merge`
//     "comment": "..."
//   }
// Unknown keys are errors (ParseError), as in the edit spec.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "app/option_schema.h"
#include "common/progress.h"
#include "common/status.h"
#include "merge/cut.h"
#include "merge/mesh_merge.h"

namespace mm::io {
struct Asset;
}

namespace mm::app {

const OptionSchema<MergeOptions>& merge_options();

struct MergeSpec {
  std::vector<MergeBoundaryPair> pairs;
  std::vector<int> fixed;
  MergeOptions options;
};

struct MergeSpecResult {
  Status status;
  MergeSpec spec;
};

// Parsing only (vertex ranges and loops are checked by merge_meshes, which knows the meshes).
MergeSpecResult parse_merge_spec(const std::string& json_text);
// The spec as JSON (what the page saves for the CLI).
std::string merge_spec_json(const MergeSpec& spec);

// Merge of two loaded assets (welded meshes), as the page's worker and the file job run it.
MergeResult merge_assets(const io::Asset& target, const io::Asset& source, const MergeSpec& spec,
                         const Progress& progress = {});

struct MergeJobFiles {
  std::string target, source, spec, out;
};

struct MergeJobRequest {
  MergeJobFiles files;
  std::function<Status(MergeOptions&)> set_overrides;  // CLI flags, applied after the spec's options
};

struct MergeJobResult {
  Status status;
  MergeStats stats;
  int vertices = 0, faces = 0, boundary_loops = 0, nonmanifold_edges = 0;
  double total_ms = 0;
};

MergeJobResult run_merge_job(const MergeJobRequest& request, const Progress& progress = {});
std::string merge_summary(const MergeJobResult& r, const std::string& out_path);

// Cut job: open a mesh with a plane (keeping the side `keep` is on; default: the side the
// normal points to) or a geodesic disk, and save it keeping the document (save_asset_with_mesh).
struct CutJobRequest {
  std::string in, out;
  bool plane = true;
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();
  bool has_keep = false;
  Eigen::Vector3d keep = Eigen::Vector3d::Zero();
  int disk_vertex = -1;
  double disk_radius = 0;  // mesh units
};

struct CutJobResult {
  Status status;
  int vertices = 0, faces = 0, boundary_loops = 0;
};

CutResult cut_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const CutJobRequest& request);
CutJobResult run_cut_job(const CutJobRequest& request);

}  // namespace mm::app
