// Hierarchical part transfer (paper 000 Sec. 4.3, Fig. 3): after the whole-body transfer
// (transfer/pose_transfer.h, "level 1"), corresponding parts of the reference and of the
// transferred source are transferred again as pairs of their own, so that their medium-scale
// pose becomes a low-frequency one, and glued back. Parts can nest (level 3, ...).
//
// Per part pair (reference region P′, source region P̃ on the level-1 result M̃):
//  1. vertex sets from the regions (mesh/part_spec.h: plane cut or geodesic disk, evaluated with
//     merge/cut.h's cut_plane / cut_disk; the source region on the source *input* mesh, whose
//     vertex ids the result shares). Same connectivity and identical region specs: the reference
//     part is the source's vertex set, so the part pair has the same connectivity too.
//  2. submeshes (faces with three part vertices); butterfly subdivision (mesh/butterfly.h) once
//     or twice when the smaller part has fewer than `min_part_vertices` vertices ("too coarse to
//     obtain usable coupled quasi-harmonic bases"), removed exactly afterwards.
//  3. Transfer I (pose_transfer) on the part pair: P̃ takes the pose of P′ (Sec. 4.2), in the
//     level-1 deformed cage with the cage vertices that hardly weigh on the part held (Sec. 5,
//     `reuse_level_cage`); a part that cage no longer encloses (a sibling glued before moved it
//     out) gets its own automatic cage (`part_cage_vertices`).
//     Landmarks: none for a same-connectivity pair (generated); otherwise the level's landmark
//     pairs inside both parts, the pair of tips (farthest from the cut) and 6 samples of the cut
//     loops matched by position (after level 1 the loops are close to each other).
//  4. registration by local frames (Sec. 4.3): each frame is built from the submesh's average
//     point, the average of its cut-boundary vertices and the vertex farthest from the boundary
//     (geodesic along edges); the transferred part is rotated so that its frame matches the
//     reference part's frame (about its boundary centroid) and moved so that its boundary
//     centroid lands on the level-1 boundary centroid.
//  5. gluing with boundary smoothing: the implicit Laplacian editor (edit/laplacian_editor.h)
//     on the level-1 mesh, with the part's inner vertices as a handle at their registered
//     positions (Laplacian coordinates "after the rotation") and the vertices within
//     `seam_rings` edges of the cut on both sides free: they keep their level-1 Laplacian
//     coordinates ("before the rotation") up to the similarities the editor derives.
//
// Automatic proposals (the paper leaves parts to the person; issue 16): the per-vertex pose
// disagreement between the level-1 result and the reference is largest on the limbs, head or
// tail that the K low frequencies did not pose. Same connectivity: after a global similarity fit,
// the rotation angle (degrees) of the best rigid fit of each vertex's 3-ring onto the
// reference's — a mis-oriented limb rotates as a whole, so the angle is high all along it and
// falls off at the joint (a plain distance grows towards the tip and spreads over the body: on
// cat-01 the region above 30% of the largest distance covered 87% of the surface). Different
// connectivity: only the landmark pairs correspond; their distance after a similarity fit, in
// units of 1/180 of the diagonal ("degrees") so one threshold serves both. From the worst
// vertex's region a tip is taken (the high-disagreement vertex farthest from the centroid, or
// the landmark itself), and a geodesic disk around it is grown to a neck: along the geodesic
// isolines from the tip, the cut is at the narrowest isoline (shortest perimeter; the latest
// within 10% of it) between `neck_window_begin` and `neck_window_end` times the high-disagreement
// region's geodesic extent from the tip, and before the isoline perimeter grows past
// `neck_ratio` × the narrowest so far (the limb meets the body) or the disk exceeds
// `max_part_area` of the surface; disks under `min_part_fraction` of the vertices are dropped.
// Proposals are returned as Disk part pairs (ranked by disagreement) that a person can accept,
// edit, or pass back. part_transfer with automatic parts proposes with several neck windows
// (more_proposal_windows), transfers each distinct set from the level-1 result and keeps the
// set whose level landmark pairs end closest to the reference (on the ten same-connectivity
// pairs measured, the summed gain went from 25 to 123 percentage points natively), then
// proposes again on that result (proposal_rounds; docs/transfer.md has the measurements).
// Experimental: measured on the Sumner/TOSCA pairs only (docs/transfer.md).
//
// Quality gate (reject_worse_parts): a glued part is kept only if the result keeps within the
// fold bound (self-intersecting pairs ≤ max(reference + source, count before the part)), adds
// no flipped face, leaves no seam (mean dihedral-angle change across its cut ≤
// max_seam_dihedral_mean) and does not increase the aligned error of the level's landmark pairs
// (generated farthest-point pairs for same connectivity); otherwise the part keeps its previous
// shape and its report says why. So the parts never add flips, nor self-intersections beyond
// the bound; level 1's own folds are reported (folds_level1).
//
// Folds: fold_report() (transfer/pose_transfer.h) counts self-intersecting triangle pairs of the
// reference, the source and a result, and locally flipped faces of the result against the source.
//
// Status codes: those of pose_transfer for level 1; InvalidArgument for a region that selects
// nothing, out-of-range seeds/vertices, bad radii; Cancelled. A part whose own transfer fails
// (too few landmarks, eigensolver) is skipped: the result keeps its level-1 shape there and the
// part's report carries the status.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"
#include "edit/laplacian_editor.h"
#include "mesh/mesh.h"
#include "mesh/part_spec.h"
#include "transfer/pose_transfer.h"

namespace mm {

struct PartTransferOptions {
  PoseTransferOptions transfer;  // Transfer I for level 1 and every part (paper defaults)
  int part_cage_vertices = 200;  // automatic cage per part (Table 1: 166–520 for whole bodies)
  // Its offset grid (cells along the longest side; whole body: 80). 32, not 48: the cage is most
  // of a part's time; measured over the seven in-repo pairs with three rounds, the same errors
  // (summed −188 vs −176 points) in ~25 % less time (docs/transfer.md).
  int part_cage_resolution = 32;
  // Paper 000 Sec. 5: "we reuse the resulting cage from the last transfer as the cage of all local
  // parts ... we always fix those cage vertices that are far away from the part". true: a part
  // takes the level-1 deformed cage when that cage still encloses it (a part next to one glued
  // before may stick out: then it gets its own cage), and the cage vertices that carry the least
  // of the part's mean-value weight, up to `reused_cage_fixed_weight` of it, are held
  // (PoseTransferOptions::fixed_cage_weight). Measured over the seven in-repo pairs (three
  // rounds): the same errors as own cages (summed gain 188.8 vs 188.0 points) in 15 % less time;
  // holding vertices by distance from the part (0.25 of its diagonal) instead held all 450 on
  // small parts, and 0.05 of the weight lost 5 points (docs/transfer.md).
  bool reuse_level_cage = true;
  double reused_cage_fixed_weight = 0.01;
  int min_part_vertices = 2000;  // subdivide a part while it has fewer vertices than this
  int max_subdivisions = 2;      // paper: "once or twice"; 0 = never
  int seam_rings = 3;            // edges on each side of a cut that the gluing step smooths (≥ 1)
  // Keep a glued part only when the result stays within issue 16's fold bound (no more
  // self-intersecting pairs than the reference and the source together, or than before the
  // part when level 1 already exceeds it), adds no flipped face, and does not move the level's
  // landmark pairs away from the reference (aligned error); a rejected part keeps the previous
  // shape and says why in its report.
  bool reject_worse_parts = true;
  double max_seam_dihedral_mean = 20; // ... and leaves no seam: mean dihedral-angle change across the cut ≤ this (degrees)
  // A part whose Transfer I folds faces (flips against its level-1 shape: different-connectivity
  // parts with their 7–8 landmarks do) is registered rigidly instead: its level-1 shape turned
  // about its cut's centre by the rotation that maps its landmark pairs best onto the reference
  // part's (Kabsch), then glued and gated like any part. false: such parts go through as they
  // are (and the gate rejects them for their flips).
  bool rigid_when_folded = true;
  // Automatic proposals.
  // At most this many proposed parts per set (one level). 6, not 4 (twenty-first session): with
  // three proposal sets, the summed gain over the seven in-repo pairs went from 189 to 263
  // points in 14 % more time, and the held-out michael9 → michael3 keeps parts (−26 %); 8 parts
  // gave 292 points in 23 % more time again but cat-07 fell to −24 % (docs/transfer.md).
  int max_parts = 6;
  double min_disagreement = 15;  // propose only where the disagreement exceeds this (degrees; see header)
  int disagreement_rings = 3;    // neighbourhood of the local rotation fit (same connectivity)
  double blob_fraction = 0.5;    // high-disagreement region: ≥ this × the worst vertex's value
  double neck_window_begin = 0.75; // the neck is searched between these multiples of the
  double neck_window_end = 1.5;    // high-disagreement region's geodesic extent from the tip
  double neck_ratio = 2.0;       // isoline perimeter growth (× narrowest so far) that marks the body
  double max_part_area = 0.3;    // a proposed part covers at most this fraction of the surface
  double min_part_fraction = 0.03; // ... and at least this fraction of the vertices
  double max_registration_degrees = 45; // larger local-frame rotations are not applied (tapered over ±15°; see .cpp)
  // --parts auto also tries these neck windows and area limits (begin, end, max_part_area): where
  // a limb turns at its root, a cut closer to the tip leaves the turning joint outside the part
  // and the seam must bend. Each distinct proposal is transferred and glued from the same level-1
  // result, and the one whose level landmark pairs land closest to the reference (the gate's
  // measure) is kept. Empty = only the window above.
  struct ProposalWindow {
    double neck_window_begin, neck_window_end, max_part_area;
  };
  std::vector<ProposalWindow> more_proposal_windows = {{1.25, 2.5, 0.3}, {1.5, 3.0, 0.3}, {1.25, 2.5, 0.4}, {1.5, 3.0, 0.4}};
  int proposal_sets = 3;         // at most this many sets: the window above, then more_proposal_windows in order (1 = one set; 5 with 6 parts: 277 points in 32 % more time)
  double proposal_tie = 0.01;    // a later set must end ≥ this fraction closer to be kept instead
  // Rounds of proposals (automatic parts only): after a round keeps its best set, the disagreement
  // is measured again on that result and new sets are proposed, each run after the parts kept so
  // far; a round is kept when its best set lands ≥ proposal_tie closer, and the rounds stop at the
  // first that does not. The parts of all kept rounds run one after the other from level 1, so
  // the parts file written (--parts-out) gives the same result. 1 = one round.
  int proposal_rounds = 3;
};

struct PartReport {
  std::string name;
  int level = 2;                 // 2 = first part level
  Status status;                 // ok, or why the part was skipped (level-1 shape kept there)
  int source_vertices = 0;       // part sizes before subdivision
  int reference_vertices = 0;
  int subdivisions = 0;          // butterfly levels applied
  int landmarks = 0;             // landmark pairs of the part transfer (generated when same connectivity)
  int seam_vertices = 0;         // vertices smoothed by the gluing step
  double rotation_degrees = 0;   // registration rotation (local frames, or the landmarks' when rigid)
  int round = 1;                 // automatic parts: the proposal round that gave it
  int transfer_flips = 0;        // faces the part's Transfer I flipped (or collapsed) against its level-1 shape
  bool rigid = false;            // registered rigidly instead (PartTransferOptions::rigid_when_folded)
  bool cage_reused = false;      // its transfer ran in the level-1 cage (PartTransferOptions::reuse_level_cage)
  int fixed_cage_vertices = 0;   // ... of which these were held
  bool transfer_reused = false;  // this part pair on these positions was transferred before (in another set or round): that result, bit for bit
  // Seam: |change of dihedral angle| (degrees, against the source input) across the edges that
  // join the part to the rest, mean and max, after gluing and before this part was transferred.
  double seam_dihedral_mean = 0, seam_dihedral_max = 0;
  double seam_dihedral_mean_before = 0, seam_dihedral_max_before = 0;
  double ms = 0;                 // wall time of this part
  PoseTransferTimings transfer_ms; // of its Transfer I
  double glue_ms = 0;            // registration and gluing (editor precompute + solves)
  // Quality gate (PartTransferOptions::reject_worse_parts): the level's landmark pairs' aligned
  // error (metrics/transfer_metrics.h) before and after gluing this part, and the self-
  // intersecting pairs and flipped faces the part added; rejected parts keep the previous shape.
  double landmark_error_before = 0, landmark_error_after = 0;
  int self_intersections_added = 0, flips_added = 0;
  int flips_repaired = 0;  // flipped (or collapsed) faces the glued part had that the flip repair removed before the gate
  bool rejected = false;
};

struct PartTransferResult {
  Status status;
  Eigen::MatrixXd V;             // #V_source by 3 final result
  Eigen::MatrixXd V_level1;      // #V_source by 3 whole-body result (level 1)
  PoseTransferResult level1;     // the level-1 transfer (timings, cage, landmarks)
  PartsSpec parts;               // the parts used (given, or proposed)
  std::vector<double> disagreement; // per source vertex, bbox-diagonal units (proposals only)
  std::vector<PartReport> reports; // per part, in transfer order (depth first)
  FoldReport folds_level1, folds; // of the level-1 and the final result
  // Automatic proposals: distinct proposal sets transferred (one per window that gave new parts),
  // the one kept (0 = the first window), and the level landmark pairs' aligned error of level 1
  // and of the result.
  int proposals_tried = 0, proposal_kept = 0;
  int proposal_rounds = 0;       // rounds that kept a set (PartTransferOptions::proposal_rounds)
  double landmark_error_level1 = 0, landmark_error = 0;
  double ms_level1 = 0, ms_parts = 0, ms_total = 0;
  // PoseTransferOptions::fold_retry_resolution, applied to the whole two-level result: when the
  // parts on the usual level-1 cage end with flipped faces or new self-intersections, level 1
  // runs again with its cage on the finer grid — and its parts, if that level 1 folds less than
  // the first — and the result with fewer violations is kept (`first` = the folds of the first
  // pass).
  FoldRetry fold_retry;
  // PoseTransferOptions::flip_repair_rings, applied to the result returned (after the retry).
  FlipRepair flip_repair;
};

// The vertex set (ascending) a region selects on mesh (V, F). InvalidArgument when it selects
// nothing or its seed is out of range.
Status part_vertices(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const PartRegion& region,
                     std::vector<int>* vertices);

// Proposed part pairs for the level-1 result `transferred` (#V_source by 3, source faces) of
// `source` towards `reference` (see header). landmarks: the level's pairs (unused when the
// meshes have the same connectivity). *disagreement (optional) gets the per-vertex field.
PartsSpec propose_parts(const Mesh& reference, const Mesh& source, const Eigen::MatrixXd& transferred,
                        const std::vector<LandmarkPair>& landmarks, const PartTransferOptions& opt = {},
                        std::vector<double>* disagreement = nullptr);

// Level 1 + parts. spec: the part pairs, or null for automatic proposals.
PartTransferResult part_transfer(const Mesh& reference, const Mesh& source, const std::vector<LandmarkPair>& landmarks,
                                 const PartsSpec* spec, const PartTransferOptions& opt = {},
                                 const Progress& progress = {});

}  // namespace mm
