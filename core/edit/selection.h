// Vertex selections for editing: explicit index lists or geometric selectors (sphere, box,
// k-ring, geodesic disk), so that a person never types thousands of indices.
//
// A selection is the UNION of all its parts. Results are sorted ascending without duplicates.
// Distances and radii are in mesh units (the CLI may scale them by the bounding-box diagonal
// before calling; see native/commands/edit.cpp). Conventions of V/F: mesh/mesh.h.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct VertexSelection {
  struct Sphere {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();  // ball center (mesh units)
    double radius = 0;                                 // ≥ 0; vertices with |v - c| ≤ radius
  };
  struct Box {
    Eigen::Vector3d min = Eigen::Vector3d::Zero();  // axis-aligned box corners, min ≤ max per axis
    Eigen::Vector3d max = Eigen::Vector3d::Zero();
  };
  struct Ring {
    int vertex = 0;  // seed vertex index
    int k = 1;       // ≥ 0 edges from the seed (0 = the seed only)
  };
  struct Slab {
    int axis = -1;      // 0, 1, 2 = x, y, z; -1 = the longest axis of the bounding box
    double from = 0;    // relative position along the axis: 0 = bbox min, 1 = bbox max
    double to = 1;      // vertices with from ≤ t ≤ to are selected (from ≤ to)
  };
  struct GeodesicDisk {
    int vertex = 0;     // seed vertex index
    double radius = 0;  // ≥ 0; shortest edge-path length from the seed (an upper bound of the
                        // geodesic distance, within a few % on good meshes)
  };

  std::vector<int> indices;  // explicit vertex indices, each in [0, #V)
  std::vector<Sphere> spheres;
  std::vector<Box> boxes;
  std::vector<Ring> rings;
  std::vector<GeodesicDisk> disks;
  std::vector<Slab> slabs;

  bool empty() const {
    return indices.empty() && spheres.empty() && boxes.empty() && rings.empty() && disks.empty() && slabs.empty();
  }
};

struct SelectionResult {
  Status status;              // InvalidArgument for out-of-range seeds/indices or bad radii
  std::vector<int> vertices;  // sorted, unique
};

// V: #V by 3, F: #F by 3. An empty selection gives an empty (ok) result; a selection whose
// parts match no vertex also gives an empty result — callers decide whether that is an error.
SelectionResult select_vertices(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                const VertexSelection& selection);

// Vertices of every connected component (through shared edges) that contains a seed, sorted.
std::vector<int> components_containing(const Eigen::MatrixXi& F, int num_vertices,
                                       const std::vector<int>& seeds);

}  // namespace mm
