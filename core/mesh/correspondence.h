// Sparse correspondences between two meshes: pairs of vertex indices (landmarks picked by hand,
// read from a file, or generated). Plain data shared by the spectral algorithms and the readers.
#pragma once

namespace mm {

struct LandmarkPair {
  int reference = -1;  // vertex index on the reference mesh
  int source = -1;     // vertex index on the source mesh
};

}  // namespace mm
