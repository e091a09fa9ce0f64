// The transfer job (paper 000, spectral pose transfer): its options schema, and the whole job on
// files — load the reference, the source, landmarks and an optional cage, run pose_transfer,
// write the posed source (keeping the rest of its document) and optionally the deformed cage.
// The CLI runs it as is; the wasm binding works on meshes the worker already holds and shares
// the schema; the bench times the same stages.
#pragma once

#include <string>
#include <vector>

#include "app/option_schema.h"
#include "common/progress.h"
#include "common/status.h"
#include "transfer/part_transfer.h"
#include "transfer/pose_transfer.h"

namespace mm::app {

// Every option of the transfer job; defaults from PoseTransferOptions (the paper's values).
const OptionSchema<PoseTransferOptions>& transfer_options();

// Options of hierarchical part transfer (`--parts`): the PartTransferOptions fields other than
// `transfer` (which transfer_options() covers); defaults from PartTransferOptions.
const OptionSchema<PartTransferOptions>& transfer_part_options();

struct TransferJobFiles {
  std::string reference;  // mesh in the wanted pose
  std::string source;     // mesh to pose (its document is kept in the output)
  std::string out;        // posed source, format by extension
  std::string landmarks;  // {"pairs": [[reference_vertex, source_vertex], ...]}; "" = none
  std::string cage;       // closed cage around the source; "" = automatic
  std::string cage_out;   // also write the deformed cage; "" = no
  std::string parts;      // "" = one level; "auto" = proposed parts; else a part-pair file (io/parts_file.h)
  std::string parts_out;  // write the part pairs used (or, without `parts`, those proposed); "" = no
};

struct TransferJobResult {
  Status status;
  PoseTransferResult transfer;
  int landmark_pairs = 0;  // pairs read from the landmarks file
  bool hierarchical = false;  // parts were transferred (then `parts` holds the whole run)
  PartTransferResult parts;   // level 1 + parts (hierarchical) or just the proposals (parts_out)
  FoldReport folds;           // of the written result
};

TransferJobResult run_transfer_job(const TransferJobFiles& files, const PoseTransferOptions& options,
                                   const Progress& progress = {});
// The same with part-transfer options (their `transfer` member is replaced by `options`).
TransferJobResult run_transfer_job(const TransferJobFiles& files, const PoseTransferOptions& options,
                                   const PartTransferOptions& part_options, const Progress& progress = {});

// One line per stage for the CLI and the batch report ("transfer (yin): 21887 vertices, ...").
std::string transfer_summary(const TransferJobResult& r, const PoseTransferOptions& options);

}  // namespace mm::app
