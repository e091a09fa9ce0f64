// PLY reader and writers (io-internal; the public entry points are in io/asset.h).
//
// Read: ascii, binary_little_endian and binary_big_endian 1.0; any elements and properties
// (all are kept for write-back); `vertex` needs x, y, z (any numeric type); `face` needs a list
// `vertex_indices` or `vertex_index` (any integer count and index type); polygons are
// fan-triangulated. Header counts larger than the data, indices out of range and polygons with
// fewer than 3 corners are ParseError.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "io/asset.h"
#include "io/document.h"

namespace mm::io {

enum class PlyType : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;        // value type (list items for lists)
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;    // lists only
  std::vector<double> values;             // all values (every PLY type fits a double exactly)
  std::vector<uint32_t> offsets;          // lists only: #count+1 offsets into values
};

struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> properties;
  int find(const std::string& property) const;  // index or -1
};

class PlyDocument : public Document {
 public:
  PlyDocument() : Document(Format::Ply) {}
  PlyEncoding encoding = PlyEncoding::BinaryLittleEndian;
  std::string header;                 // header text through "end_header\n", written back as is
  std::vector<PlyElement> elements;   // in file order, with their data
  int vertex_element = -1;
  int face_element = -1;              // -1 for a point cloud
  int face_list = -1;                 // property index of vertex_indices / vertex_index
};

// Fills asset->V_raw, F_raw, warnings and document from PLY bytes.
Status load_ply(const std::vector<uint8_t>& bytes, Asset* asset);

// Writes the source PLY back in its own encoding with new raw positions; nx/ny/nz are
// recomputed when recompute_normals is set and positions changed; all else is kept.
Status save_ply_document(const PlyDocument& doc, const Eigen::MatrixXi& F_raw,
                         const Eigen::MatrixXd& V_raw_new, bool positions_changed,
                         const SaveOptions& opt, std::vector<uint8_t>* out);

// Neutral layout of a PLY document with new positions (normals and red/green/blue kept).
ExportMesh ply_export_mesh(const PlyDocument& doc, const Eigen::MatrixXi& F_raw,
                           const Eigen::MatrixXd& V_raw_new, bool recompute_normals);

// Writes a binary little-endian PLY (float x y z, optional float nx ny nz and uchar colors,
// uchar/int face lists) from a neutral mesh.
Status write_ply(const ExportMesh& mesh, std::vector<uint8_t>* out);

}  // namespace mm::io
