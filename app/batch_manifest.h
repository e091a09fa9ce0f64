// Batch manifests (`meshmorph batch MANIFEST.json`, docs/batch.md): a JSON document naming jobs
// of every kind the app tier has, expanded here into a flat, deterministic job list. Parsing and
// expansion only — running is app/batch_run.h, the worker app/batch_worker.h.
//
//   {
//     "output":  "out/{kind}/{target}/{clip}.glb",  default output pattern of every group (optional)
//     "summary": "out/summary.json",               summary path (default: <manifest stem>.summary.json
//                                                   next to the manifest); state and table sit next to it
//     "retarget": [ { "sources": [SRC, ...] | "source": SRC,
//                     "clips": "*" | [NAME, ...] | NAME,       "*" = every clip of each source
//                     "targets": [TARGET, ...] | "target": TARGET,
//                     "options": { any option of `meshmorph options retarget` but "clip" },
//                     "output": PATTERN, "name": TEXT, "comment": TEXT } ],
//        TARGET: "path" | { "path": P, "joints": J.json, "joint_map": M.json, "name": TEXT }
//     "transfer": [ { "pairs": [ { "reference": R, "source": S, "landmarks": L.json, "cage": C,
//                                  "ground_truth": G } ]      (or one pair's keys directly in the group)
//                     "options": {...}, "output": PATTERN, "name": TEXT, "comment": TEXT } ],
//     "edit":  [ { "input": MESH, "specs": [SPEC, ...] | "spec": SPEC, "options": {...}, ... } ],
//     "merge": [ { "target": T, "source": S, "spec": SPEC, "options": {...}, ... } ],
//     "comment": TEXT
//   }
//
// Paths are relative to the manifest's folder. Output patterns take {kind}, {name} (the group's
// "name"), {ext} (the main input's extension; "glb" for retarget) and per kind: retarget {source}
// {clip} {target}; transfer {source} {reference}; edit {input} {spec}; merge {target} {source}
// {spec} — file stems (or the target's "name"), with characters other than letters, digits,
// '.', '-', '_' replaced by '_'. A group's "options" are read through the job's options schema
// (the CLI's flags); for edit and merge they win over the spec's "options", like CLI flags.
// Unknown keys are errors (ParseError), as in edit and merge specs; so are two jobs writing the
// same file and a job whose output is one of its inputs.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "common/status.h"

namespace mm::app {

enum class BatchKind { Retarget, Transfer, Edit, Merge };
const char* batch_kind_name(BatchKind k);  // "retarget", "transfer", "edit", "merge"

struct BatchJob {
  int index = 0;            // position in the manifest's job list (summary order, sharding)
  std::string id;           // unique and stable: the output path as the pattern gave it
  BatchKind kind = BatchKind::Retarget;
  std::string label;        // short readable name: "Knight/Walking_A -> Barbarian"
  // Input files by role (resolved paths): retarget source, target, target_joints, joint_map;
  // transfer reference, source, landmarks, cage, ground_truth; edit input, spec; merge target,
  // source, spec. Absent roles are not in the map.
  std::map<std::string, std::string> files;
  std::string clip;         // retarget: the source clip
  std::string options_json; // the group's "options" object, compact JSON with sorted keys ("{}")
  std::string output;       // resolved output path
  // Jobs with the same group (retarget: source, target, joints, options) share one
  // precomputation in a worker; "" = none to share.
  std::string group;
  // A job that cannot run as given (a source whose clips cannot be listed for "*"): reported as
  // failed with this status, never started.
  Status preflight;
};

struct BatchManifest {
  std::string path;          // the manifest file as given
  std::string dir;           // its folder (base of relative paths)
  std::string summary_path;  // resolved
  std::vector<BatchJob> jobs;
  std::vector<std::string> warnings;  // e.g. a clip name repeated in a source (only the first is reachable)
};

struct BatchManifestResult {
  Status status;
  BatchManifest manifest;
};

// Lists the clip names of an animated source (for "clips": "*"), in file order.
using ClipLister = std::function<Status(const std::string& source_path, std::vector<std::string>* clips)>;
// The default lister: loads the glTF and reads its character (io::animated_character).
Status list_source_clips(const std::string& source_path, std::vector<std::string>* clips);

// Parses manifest text; `manifest_path` locates relative paths and names the default summary.
BatchManifestResult parse_batch_manifest(const std::string& text, const std::string& manifest_path,
                                         const ClipLister& list_clips = list_source_clips);
// Reads the file (io::read_file) and parses it.
BatchManifestResult load_batch_manifest(const std::string& manifest_path, const ClipLister& list_clips = list_source_clips);

// The characters kept from a placeholder value in an output path ('/' and the rest become '_').
std::string batch_path_component(const std::string& value);

}  // namespace mm::app
