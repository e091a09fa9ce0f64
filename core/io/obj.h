// OBJ reader and writers (io-internal; the public entry points are in io/asset.h).
//
// Read: `v x y z [w | r g b]`, `vt u v [w]`, `vn x y z`, `f` with the a, a/b, a//c and a/b/c
// corner forms and negative (relative) indices; polygons are fan-triangulated (corner 0 with
// each later edge). Every other line (o, g, s, usemtl, mtllib, l, p, comments) is kept for
// write-back. Indices 0 or beyond the elements defined so far are ParseError.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "io/asset.h"
#include "io/document.h"

namespace mm::io {

class ObjDocument : public Document {
 public:
  ObjDocument() : Document(Format::Obj) {}
  std::vector<std::string> lines;  // every line of the file, without its ending
  std::vector<int> v_line;         // line index of each `v`
  std::vector<int> vn_line;        // line index of each `vn`
  Eigen::MatrixXd VT;              // #vt by 2 (u, v as in the file: v grows upwards)
  Eigen::MatrixXd VN;              // #vn by 3 as in the file
  Eigen::MatrixXi F_vt;            // per triangle of F_raw: vt index of each corner, -1 if none
  Eigen::MatrixXi F_vn;            // per triangle of F_raw: vn index of each corner, -1 if none
  bool crlf = false;               // the file used \r\n line endings
};

// Fills asset->V_raw, F_raw, warnings and document from OBJ bytes.
Status load_obj(const std::vector<uint8_t>& bytes, Asset* asset);

// Writes the source OBJ back with new raw positions (#V_raw by 3): `v` lines get the new
// coordinates (extra values such as colors kept), `vn` lines are recomputed when
// recompute_normals is set and positions changed, every other line is kept as it was.
Status save_obj_document(const ObjDocument& doc, const Eigen::MatrixXi& F_raw,
                         const Eigen::MatrixXd& V_raw_new, bool positions_changed,
                         const SaveOptions& opt, std::vector<uint8_t>* out);

// Neutral layout of an OBJ document with new positions: vertices split per distinct
// (v, vt, vn) corner so that UVs and normals become per-vertex attributes.
// Normals are the file's, or recomputed per `vn` group when `recompute_normals` is set.
ExportMesh obj_export_mesh(const ObjDocument& doc, const Eigen::MatrixXi& F_raw,
                           const Eigen::MatrixXd& V_raw_new, bool recompute_normals);

// Writes a plain OBJ (v, optional vt/vn, f) from a neutral mesh.
Status write_obj(const ExportMesh& mesh, std::vector<uint8_t>* out);

}  // namespace mm::io
