// Mesh validation: every defect class a user's file can have, counted, with a first example.
//
// validate_mesh never fails: it returns a report. Methods then call require_* helpers (or
// MeshReport::status) to turn the defects they cannot handle into a Status with a message
// such as "mesh has 26 non-manifold edges, first at vertices 10-11".
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

enum class MeshDefect {
  Empty,                   // no vertices or no faces
  NonFiniteCoordinate,     // NaN or Inf in V
  IndexOutOfRange,         // face index < 0 or >= #V
  DegenerateFace,          // repeated vertex index in a face, or zero area (collinear)
  DuplicateFace,           // same vertex set as an earlier face (any order)
  NonManifoldEdge,         // edge used by more than two faces
  NonManifoldVertex,       // vertex whose incident faces form more than one fan
  UnreferencedVertex,      // vertex used by no face
  InconsistentOrientation, // directed edge appears twice (neighbouring faces with opposite winding)
};

const char* mesh_defect_name(MeshDefect d);

struct DefectReport {
  MeshDefect defect;
  int count = 0;        // how many vertices / faces / edges have it
  std::string example;  // first instance, e.g. "face 17 (vertices 3, 3, 9)"
};

struct MeshReport {
  int num_vertices = 0;
  int num_faces = 0;
  int num_edges = 0;                   // undirected edges among valid faces
  Eigen::Vector3d bbox_min{0, 0, 0};   // over finite coordinates
  Eigen::Vector3d bbox_max{0, 0, 0};
  double bbox_diagonal = 0;
  std::vector<DefectReport> defects;   // only defects with count > 0, in MeshDefect order
  int num_components = 0;              // over referenced vertices
  std::vector<int> component_sizes;    // faces per component, component order of vertex_components
  std::vector<std::vector<int>> boundary_loops;  // see mesh/topology.h
  int euler_characteristic = 0;        // V - E + F over referenced vertices
  bool closed() const { return boundary_loops.empty(); }

  // Count of a defect (0 when absent).
  int count(MeshDefect d) const;
  // First defect among `fatal` as an InvalidMesh status, or ok.
  Status status(const std::vector<MeshDefect>& fatal) const;
  // Human-readable multi-line report (used by `meshmorph info`).
  std::string to_text() const;
};

struct ValidateOptions {
  // A face is degenerate when its area is below this fraction of the squared bbox diagonal.
  double degenerate_area_tolerance = 1e-14;
};

MeshReport validate_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                         const ValidateOptions& opt = {});

// Defects no method can work with: Empty, NonFiniteCoordinate, IndexOutOfRange.
const std::vector<MeshDefect>& fatal_defects();
// Defects that break methods needing a 2-manifold surface (adds NonManifold*, Degenerate).
const std::vector<MeshDefect>& manifold_defects();

// Shorthand: validate and return the status for `fatal` defects.
Status check_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                  const std::vector<MeshDefect>& fatal = fatal_defects());

}  // namespace mm
