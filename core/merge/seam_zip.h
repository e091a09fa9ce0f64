// Zipping a deformed source onto a target along merged boundary curves (paper 001 Sec. 5.1,
// after [SLCO*04]): remove the band of target triangles touching each target loop, triangulate
// the gap between the target's new boundary and the source loop by advancing along both curves
// (shortest diagonal first), and smooth the seam with the umbrella operator [Tau95].
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "merge/mesh_merge.h"

namespace mm {

// One seam: a target loop in its own orientation and the source loop that lands on it,
// traversed along it (i.e. against the source's face orientation), source_loop[0] matching
// target_loop[0].
struct SeamCurves {
  std::vector<int> target_loop;
  std::vector<int> source_loop;
};

struct ZipOptions {
  bool enabled = true;
  int smoothing_iterations = 3;
  int smoothing_rings = 2;
  double smoothing_step = 0.5;
  // Transition regions (merge/transition.h), mesh units; both > 0 turns them on (before the
  // umbrella smoothing, which then only evens out the zip strip).
  double transition_target_width = 0;
  double transition_source_width = 0;
};

struct ZipResult {
  Status status;
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  std::vector<int> target_map;  // per target vertex: index in V or -1
  int source_offset = 0;
  std::vector<MergeSeamReport> seams;
  int transition_vertices = 0;  // vertices rebuilt by the transition regions
};

ZipResult zip_meshes(const Eigen::MatrixXd& Vt, const Eigen::MatrixXi& Ft, const Eigen::MatrixXd& Vs,
                     const Eigen::MatrixXi& Fs, const std::vector<SeamCurves>& seams, const ZipOptions& opt);

// Dihedral angles (degrees) across the edges of `faces` (angle between the normals of the two
// faces sharing each edge; boundary edges skipped): max and mean.
void seam_dihedral_angles(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<int>& faces,
                          double* max_deg, double* mean_deg);

}  // namespace mm
