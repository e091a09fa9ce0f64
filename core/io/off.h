// OFF reader and writers (io-internal; the public entry points are in io/asset.h).
//
// Read: header keyword [ST][C][N]OFF (COFF colors, NOFF normals tolerated), `#` comments,
// counts on the keyword line or the next one, one vertex per line (x y z, then anything that
// is kept verbatim), one face per line (n i_1 .. i_n [color]) fan-triangulated. Binary OFF and
// 4OFF/nOFF are Unsupported. Counts larger than the data and indices out of range are ParseError.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "io/asset.h"
#include "io/document.h"

namespace mm::io {

class OffDocument : public Document {
 public:
  OffDocument() : Document(Format::Off) {}
  std::string keyword = "OFF";              // header keyword as found (e.g. "COFF")
  std::vector<std::string> comments;        // comment lines before the counts, kept on write-back
  std::vector<std::string> vertex_extra;    // per vertex: text after x y z (colors, normals)
  std::vector<std::string> face_lines;      // per polygon: the face line as found (comment stripped)
  std::vector<int> face_triangles;          // per polygon: number of triangles it became
};

// Fills asset->V_raw, F_raw, warnings and document from OFF bytes.
Status load_off(const std::vector<uint8_t>& bytes, Asset* asset);

// Writes the source OFF back with new raw positions; everything else as read.
Status save_off_document(const OffDocument& doc, const Eigen::MatrixXd& V_raw_new,
                         std::vector<uint8_t>* out);

// Writes a plain OFF (or COFF when colors are given) from a neutral mesh.
Status write_off(const ExportMesh& mesh, std::vector<uint8_t>* out);

}  // namespace mm::io
