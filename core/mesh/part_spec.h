// Part pairs for hierarchical pose transfer (paper 000 Sec. 4.3): how a part is selected on
// the reference and on the source, nested into levels. Plain data shared by the transfer
// algorithm (transfer/part_transfer.h, which turns a region into a vertex set) and the JSON
// reader/writer (io/parts_file.h).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace mm {

enum class PartRegionKind {
  Plane,     // the vertices on the `keep` side of a plane (connected piece nearest `keep`), merge/cut.h
  Disk,      // the geodesic disk (along edges) of radius `radius` around vertex `seed`
  Vertices,  // an explicit vertex list
};

struct PartRegion {
  PartRegionKind kind = PartRegionKind::Disk;
  Eigen::Vector3d point{0, 0, 0};   // Plane: a point on the plane (mesh units of the mesh it selects on)
  Eigen::Vector3d normal{0, 0, 1};  // Plane: normal (any length > 0)
  Eigen::Vector3d keep{0, 0, 0};    // Plane: a point on the side to keep
  int seed = -1;                    // Disk: centre vertex
  double radius = 0;                // Disk: geodesic radius as a fraction of the mesh's bbox diagonal (> 0)
  std::vector<int> vertices;        // Vertices
};

// One part pair. The source region is evaluated on the source *input* mesh (its vertex ids are
// those of the transferred source); the reference region on the reference. Children are
// transferred after their parent, inside the result of the parent's level.
struct PartPair {
  std::string name;            // for reports ("front left leg"); may be empty
  PartRegion reference;
  PartRegion source;
  std::vector<PartPair> children;
};

struct PartsSpec {
  std::vector<PartPair> parts;  // second level; their children form the third, and so on
};

}  // namespace mm
