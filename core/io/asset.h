// Asset: a loaded mesh file that remembers its whole document, so that saving writes back
// everything unchanged except the positions (and normals) of what was computed.
//
// Supported: glTF 2.0 (.gltf with external or data-URI buffers, .glb), OBJ (polygons
// fan-triangulated), OFF, PLY (ascii, binary little/big endian).
//
// glTF: all TRIANGLES primitives of the default scene (or scene 0) are loaded, in node
// traversal order, with their node's world transform applied (V_raw is in world space).
// Other primitive modes (points, lines, strips, fans) make the load fail with Unsupported
// unless LoadOptions::skip_unsupported_primitives is set (then they are left untouched).
// The raw layout (V_raw/F_raw) concatenates primitives; the geometry mesh every algorithm
// uses is the welded one (glTF splits vertices at UV/normal seams; see mesh/weld.h).
//
// Skinned primitives are in their rest pose: the skin applied at the nodes' own transforms, as
// glTF viewers draw them (glTF 2.0: a skinned mesh is placed by its joints, not by its node).
// Where that equals the bind pose as placed by the node (every character in data/ but
// RobotExpressive's hands, whose bind pose has the arms spread), V_raw is the node's world
// transform of the positions, exactly; PrimitiveRef::skinned marks them, rest_skin the others.
//
// Security: external URIs of a .gltf are resolved only inside the file's own folder; absolute
// paths, "..", and URI schemes other than data: are refused with IoError before the resolver
// is asked.
//
// Status codes: IoError (file missing/unreadable/unwritable, refused or missing external URI),
// ParseError (malformed contents: empty file, truncated GLB, bad JSON, indices out of range,
// counts larger than the data, OBJ index 0), Unsupported (unknown extension, non-triangle glTF
// primitives, binary OFF, compressed glTF geometry), InvalidMesh (a glTF scene without
// triangle primitives), InvalidArgument / NumericalError (save: wrong shape or non-finite
// positions). NaN coordinates load fine; mesh/validate.h reports them.
//
// .gltf vs .glb is decided by the content ("glTF" magic), so Asset::format can differ from the
// format passed in when a file has the wrong extension.
//
// glTF documents: code inside core/io (and the retarget export) reaches the tinygltf::Model
// through io/gltf_document.h.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "mesh/mesh.h"
#include "mesh/weld.h"

namespace mm::io {

enum class Format { Gltf, Glb, Obj, Off, Ply };

// Format from a file name's extension (case-insensitive); nullopt when unknown.
std::optional<Format> format_from_path(const std::string& path);
const char* format_name(Format f);

// One loaded glTF primitive instance (or the single "primitive" of an OBJ/OFF/PLY file).
struct PrimitiveRef {
  int node = -1;           // glTF node index (-1 for non-glTF)
  int mesh = -1;           // glTF mesh index
  int primitive = -1;      // index within the mesh
  int first_vertex = 0;    // range in V_raw
  int num_vertices = 0;
  int first_face = 0;      // range in F_raw
  int num_faces = 0;
  bool skinned = false;    // node has a skin
  Eigen::Matrix4d world = Eigen::Matrix4d::Identity();  // node world transform
  // A skinned primitive whose rest pose (its skin at the nodes' own transforms, as viewers show
  // it) differs from its bind pose as placed by the node: per vertex the 3×4 affine map from mesh
  // space to world space, row-major (#num_vertices by 12); V_raw holds the rest pose and saving maps
  // positions back through it. Empty otherwise (V_raw = world × mesh-space positions).
  Eigen::MatrixXd rest_skin;
  std::string name;        // "<node name>/<mesh name>#<primitive>"
};

// Vertex v's map of a PrimitiveRef::rest_skin (mesh space → world space).
inline Eigen::Matrix<double, 3, 4> rest_skin_map(const Eigen::MatrixXd& rest_skin, Eigen::Index v) {
  Eigen::Matrix<double, 3, 4> a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a(r, c) = rest_skin(v, 4 * r + c);
  return a;
}

class Document;  // format-specific contents (tinygltf::Model, OBJ lines, PLY properties)

struct Asset {
  Format format = Format::Obj;
  std::string source_name;            // file name as given (diagnostics only)
  Eigen::MatrixXd V_raw;              // #R by 3, world space, original vertex layout
  Eigen::MatrixXi F_raw;              // triangles over V_raw
  std::vector<PrimitiveRef> primitives;
  WeldResult weld;                    // welded mesh over V_raw (weld.V, weld.F, weld.to_welded)
  std::vector<std::string> warnings;  // non-fatal issues met while loading
  std::shared_ptr<const Document> document;  // kept for saving; shared, immutable

  // The geometry mesh (welded).
  Mesh mesh() const { return {weld.V, weld.F}; }
};

struct LoadOptions {
  WeldOptions weld;                         // tolerance for welding seam-split vertices
  bool skip_unsupported_primitives = false; // glTF: leave non-triangle primitives alone
};

struct LoadResult {
  Status status;
  Asset asset;
};

// Reads external files referenced by a .gltf (buffers/images) by their URI relative to the
// .gltf. Returns false when missing. The browser passes the sibling files the user dropped.
using FileResolver = std::function<bool(const std::string& uri, std::vector<uint8_t>* bytes)>;

LoadResult load_asset(const std::string& path, const LoadOptions& opt = {});
LoadResult load_asset_from_memory(const std::vector<uint8_t>& bytes, Format format,
                                  const std::string& name, const FileResolver& resolver = {},
                                  const LoadOptions& opt = {});

struct SaveOptions {
  bool recompute_normals = true;  // glTF: NORMAL of changed primitives recomputed from the result
  // glTF: skin weights whose per-vertex sum is not 1 (which the Khronos validator reports as
  // errors; some exporters write them) are replaced by normalized copies. Valid weights are
  // never touched. Off: written back exactly as loaded.
  bool repair_weights = true;
};

// Writes the asset with new welded positions V (#W by 3, world space; pass asset.weld.V to
// keep the geometry). When the output format equals the input format, everything else in the
// document is kept (glTF: accessors, materials, textures, nodes, skins, animations; OBJ: UVs,
// normals, groups, materials; PLY: extra properties). Converting between formats keeps what
// the target format can hold. glTF output for a changed primitive gets new POSITION (and
// NORMAL) accessors in local space (inverse node transform) with correct min/max; the old
// accessors stay, so no index in the document changes. A mesh instanced by several nodes is
// copied for an instance whose new positions differ from the first instance's (gltf_save.h).
// A raw vertex whose welded position is unchanged keeps its exact original coordinates.
// .gltf saved by path writes its buffers to "<name>.bin" next to it and copies external images
// (same URI); saved to memory, buffers become data URIs. GLB output embeds everything.
Status save_asset(const Asset& asset, const Eigen::MatrixXd& V, const std::string& path,
                  const SaveOptions& opt = {});
Status save_asset_to_memory(const Asset& asset, const Eigen::MatrixXd& V, Format format,
                            std::vector<uint8_t>* bytes, const SaveOptions& opt = {});

// Writes a mesh whose topology differs from the asset's (a merge result; V, F in world space).
// glTF/GLB in and out: the document is kept (materials, textures, other nodes, skins,
// animations); the loaded triangle primitives stop being drawn (removed from their mesh, or the
// mesh detached from its nodes with its skin and morph-weight channels) and a new root node
// "merged" draws the new mesh with the material of the first loaded primitive. Otherwise a plain
// mesh in the output format.
Status save_asset_with_mesh(const Asset& asset, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                            const std::string& path);
Status save_asset_with_mesh_to_memory(const Asset& asset, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                      Format format, std::vector<uint8_t>* bytes);

// Writes a plain mesh (no source document) in the format of `path`'s extension.
// Optional per-vertex colors (#V by 3 in 0..1) are written as COLOR_0 / PLY red,green,blue.
Status save_mesh(const std::string& path, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                 const Eigen::MatrixXd& colors = {});
Status save_mesh_to_memory(Format format, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                           std::vector<uint8_t>* bytes, const Eigen::MatrixXd& colors = {});

// Reads a whole file; IoError with the path in the message when it fails.
// Reads a regular file whole. Directories, FIFOs and devices are refused (IoError), files over
// kMaxInputBytes before anything is read (Unsupported).
constexpr uint64_t kMaxInputBytes = uint64_t{2000} << 20;  // 2000 MiB
Status read_file(const std::string& path, std::vector<uint8_t>* bytes);
// Writes `bytes` to a temporary file next to `path` and renames it into place.
Status write_file_atomic(const std::string& path, const std::vector<uint8_t>& bytes);
// IoError when `path` cannot be written (missing or read-only folder, a directory): checked by
// the jobs before any long computation.
Status check_output_path(const std::string& path);

}  // namespace mm::io
