// Document: the format-specific contents an Asset keeps so that saving can write back
// everything it did not change (io-internal; code outside core/io only sees the pointer).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "io/asset.h"

namespace mm::io {

class Document {
 public:
  explicit Document(Format source) : source_format(source) {}
  virtual ~Document() = default;
  Document(const Document&) = default;
  Document& operator=(const Document&) = delete;

  // Format family of the document (Gltf and Glb share one document type); selects the
  // static_cast in the format's own code, so no RTTI is needed.
  const Format source_format;
};

// A mesh in a neutral layout for writing into a format other than the source's (conversion)
// and for save_mesh. Optional attributes are empty matrices when absent.
struct ExportMesh {
  Eigen::MatrixXd V;   // #V by 3 positions
  Eigen::MatrixXi F;   // #F by 3 triangles
  Eigen::MatrixXd N;   // #V by 3 unit normals, or empty
  Eigen::MatrixXd UV;  // #V by 2 texture coordinates in glTF convention (v grows downwards), or empty
  Eigen::MatrixXd C;   // #V by 3 colors in 0..1, or empty
};

}  // namespace mm::io
