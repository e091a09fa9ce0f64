#include "io/asset.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>

#include "io/json_text.h"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "io/document.h"
#include "io/gltf_export.h"
#include "io/gltf_load.h"
#include "io/gltf_save.h"
#include "io/obj.h"
#include "io/off.h"
#include "io/ply.h"

namespace mm::io {

std::optional<Format> format_from_path(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of("/\\");
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return std::nullopt;
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == "gltf") return Format::Gltf;
  if (ext == "glb") return Format::Glb;
  if (ext == "obj") return Format::Obj;
  if (ext == "off") return Format::Off;
  if (ext == "ply") return Format::Ply;
  return std::nullopt;
}

const char* format_name(Format f) {
  switch (f) {
    case Format::Gltf: return "glTF";
    case Format::Glb: return "GLB";
    case Format::Obj: return "OBJ";
    case Format::Off: return "OFF";
    case Format::Ply: return "PLY";
  }
  return "unknown";
}

namespace detail {

static std::string asset_parent_dir(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

}  // namespace detail

Status read_file(const std::string& path, std::vector<uint8_t>* bytes) {
  bytes->clear();
  // Only regular files: a directory, FIFO or device would be read forever or fail obscurely.
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
    return Status::error(StatusCode::IoError, "cannot open '" + quote_input(path, 200) + "': no such file");
  if (!S_ISREG(st.st_mode))
    return Status::error(StatusCode::IoError, "'" + quote_input(path, 200) + "' is not a regular file (" +
                                                  (S_ISDIR(st.st_mode) ? "a directory" : "a pipe, socket or device") + ")");
  if (static_cast<uint64_t>(st.st_size) > kMaxInputBytes)
    return Status::error(StatusCode::Unsupported, "'" + quote_input(path, 200) + "' has " + std::to_string(st.st_size) +
                                                      " bytes; files over " + std::to_string(kMaxInputBytes >> 20) +
                                                      " MiB are refused");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(StatusCode::IoError, "cannot open '" + quote_input(path, 200) + "' for reading");
  bytes->resize(static_cast<size_t>(st.st_size));
  if (st.st_size > 0 && !in.read(reinterpret_cast<char*>(bytes->data()), st.st_size))
    return Status::error(StatusCode::IoError, "cannot read '" + quote_input(path, 200) + "'");
  return Status::success();
}

Status write_file_atomic(const std::string& path, const std::vector<uint8_t>& bytes) {
  // Written next to the target, then renamed over it: a crash or a full disk leaves the old file
  // (or nothing), never a truncated one; writing onto the input's own path works.
  const std::string tmp = path + ".mm-tmp-" + std::to_string(static_cast<long long>(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Status::error(StatusCode::IoError, "cannot open '" + quote_input(path, 200) + "' for writing");
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      return Status::error(StatusCode::IoError, "cannot write '" + quote_input(path, 200) + "' (disk full?)");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return Status::error(StatusCode::IoError, "cannot replace '" + quote_input(path, 200) + "'");
  }
  return Status::success();
}

Status check_output_path(const std::string& path) {
  if (path.empty()) return Status::error(StatusCode::InvalidArgument, "no output path given");
  std::string dir = detail::asset_parent_dir(path);  // "" or ending in a separator
  if (dir.empty()) dir = ".";
  else if (dir.size() > 1) dir.pop_back();
  struct stat st;
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    return Status::error(StatusCode::IoError, "the output folder '" + quote_input(dir, 200) + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    return Status::error(StatusCode::IoError, "the output folder '" + quote_input(dir, 200) + "' is not writable");
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    return Status::error(StatusCode::IoError, "the output '" + quote_input(path, 200) + "' is a directory");
  return Status::success();
}

namespace detail {

static Status asset_write_file(const std::string& path, const std::vector<uint8_t>& bytes) {
  return write_file_atomic(path, bytes);
}


static std::string asset_stem(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = base.find_last_of('.');
  return dot == std::string::npos ? base : base.substr(0, dot);
}

static bool asset_same_family(Format a, Format b) {
  const bool ga = a == Format::Gltf || a == Format::Glb, gb = b == Format::Gltf || b == Format::Glb;
  return ga ? gb : a == b;
}

// New positions in the raw layout, after checking their shape and finiteness. A raw vertex
// counts as moved when its welded position differs from the loaded welded position; unmoved
// vertices keep their exact original coordinates (welding may have snapped near-duplicates
// together, and writing those snapped values back would change untouched data).
static Status asset_raw_positions(const Asset& asset, const Eigen::MatrixXd& V, Eigen::MatrixXd* V_raw_out,
                                  std::vector<char>* moved) {
  if (V.cols() != 3 || V.rows() != asset.weld.V.rows())
    return Status::error(StatusCode::InvalidArgument,
                         "expected " + std::to_string(asset.weld.V.rows()) + " by 3 welded positions, got " +
                             std::to_string(V.rows()) + " by " + std::to_string(V.cols()));
  for (int r = 0; r < V.rows(); ++r)
    if (!V.row(r).allFinite())
      return Status::error(StatusCode::NumericalError,
                           "refusing to save non-finite positions (first at welded vertex " + std::to_string(r) + ")");
  const Eigen::Index n = asset.V_raw.rows();
  assert(asset.weld.to_welded.size() == n && "asset.weld must cover V_raw");
  *V_raw_out = asset.V_raw;
  moved->assign(static_cast<size_t>(n), 0);
  for (Eigen::Index j = 0; j < n; ++j) {
    const int w = asset.weld.to_welded[j];
    // != is true for NaN in the loaded mesh, so replacing a NaN counts as a move.
    if ((V.row(w).array() != asset.weld.V.row(w).array()).any()) {
      V_raw_out->row(j) = V.row(w);
      (*moved)[static_cast<size_t>(j)] = 1;
    }
  }
  return Status::success();
}

static Status asset_write_export(const ExportMesh& m, Format format, std::vector<uint8_t>* bytes) {
  switch (format) {
    case Format::Obj: return write_obj(m, bytes);
    case Format::Off: return write_off(m, bytes);
    case Format::Ply: return write_ply(m, bytes);
    case Format::Gltf:
    case Format::Glb: return write_gltf_mesh(m, format, bytes);
  }
  return Status::error(StatusCode::Unsupported, "unknown output format");
}

// Everything save_asset and save_asset_to_memory share; `stem` selects sidecar files (.gltf).
static Status asset_save_impl(const Asset& asset, const Eigen::MatrixXd& V, Format format, const SaveOptions& opt,
                         const std::string& stem, GltfFiles* files) {
  Eigen::MatrixXd V_raw_new;
  std::vector<char> moved;
  Status s = asset_raw_positions(asset, V, &V_raw_new, &moved);
  if (!s.ok()) return s;
  const bool changed = std::find(moved.begin(), moved.end(), 1) != moved.end();
  const Document* doc = asset.document.get();
  if (doc && asset_same_family(doc->source_format, format)) {
    switch (doc->source_format) {
      case Format::Obj:
        return save_obj_document(static_cast<const ObjDocument&>(*doc), asset.F_raw, V_raw_new, changed, opt, &files->main);
      case Format::Off:
        return save_off_document(static_cast<const OffDocument&>(*doc), V_raw_new, &files->main);
      case Format::Ply:
        return save_ply_document(static_cast<const PlyDocument&>(*doc), asset.F_raw, V_raw_new, changed, opt,
                                 &files->main);
      case Format::Gltf:
      case Format::Glb: return save_gltf_document(asset, V_raw_new, moved, format, opt, stem, files);
    }
  }
  const bool renormal = opt.recompute_normals && changed;
  ExportMesh m;
  if (!doc) {
    m.V = V_raw_new;
    m.F = asset.F_raw;
  } else if (doc->source_format == Format::Obj) {
    m = obj_export_mesh(static_cast<const ObjDocument&>(*doc), asset.F_raw, V_raw_new, renormal);
  } else if (doc->source_format == Format::Ply) {
    m = ply_export_mesh(static_cast<const PlyDocument&>(*doc), asset.F_raw, V_raw_new, renormal);
  } else if (doc->source_format == Format::Gltf || doc->source_format == Format::Glb) {
    m = gltf_export_mesh(asset, V_raw_new, renormal);
  } else {
    m.V = V_raw_new;
    m.F = asset.F_raw;
  }
  return asset_write_export(m, format, &files->main);
}

// Writes a saved glTF's sidecars (buffers, copied images) next to `path`, then the main file.
static Status asset_write_files(const std::string& path, const GltfFiles& files) {
  const std::string dir = asset_parent_dir(path);
  for (const auto& [name, data] : files.sidecars) {
    // Image URIs may name a subfolder ("textures/a.png"); they passed the URI check at load.
    const std::filesystem::path sidecar = std::filesystem::path(dir + name);
    std::error_code ec;
    if (sidecar.has_parent_path()) std::filesystem::create_directories(sidecar.parent_path(), ec);
    Status s = asset_write_file(sidecar.string(), data);
    if (!s.ok()) return s;
  }
  return asset_write_file(path, files.main);
}

static Status asset_save(const Asset& asset, const Eigen::MatrixXd& V, Format format, const SaveOptions& opt,
                         const std::string& stem, GltfFiles* files) {
  try {
    return asset_save_impl(asset, V, format, opt, stem, files);
  } catch (const std::bad_alloc&) {
    return Status::error(StatusCode::IoError, "out of memory while saving");
  } catch (const std::exception& e) {
    return Status::error(StatusCode::IoError, std::string("saving failed: ") + e.what());
  }
}

static Status asset_check_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXd& colors) {
  if (V.cols() != 3) return Status::error(StatusCode::InvalidArgument, "V must be #V by 3");
  if (F.size() > 0 && F.cols() != 3) return Status::error(StatusCode::InvalidArgument, "F must be #F by 3");
  if (colors.size() > 0 && (colors.rows() != V.rows() || colors.cols() != 3))
    return Status::error(StatusCode::InvalidArgument, "colors must be #V by 3");
  for (int r = 0; r < V.rows(); ++r)
    if (!V.row(r).allFinite())
      return Status::error(StatusCode::NumericalError,
                           "refusing to save non-finite positions (first at vertex " + std::to_string(r) + ")");
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (F(f, c) < 0 || F(f, c) >= V.rows())
        return Status::error(StatusCode::InvalidArgument, "face " + std::to_string(f) + " references vertex " +
                                                              std::to_string(F(f, c)) + " of " +
                                                              std::to_string(V.rows()));
  return Status::success();
}

}  // namespace detail

namespace detail {
static LoadResult asset_load(const std::vector<uint8_t>& bytes, Format format, const std::string& name,
                             const FileResolver& resolver, const LoadOptions& opt) {
  LoadResult r;
  Asset& a = r.asset;
  a.format = format;
  a.source_name = name;
  if (bytes.empty()) {
    r.status = Status::error(StatusCode::ParseError, name + ": file is empty");
    return r;
  }
  switch (format) {
    case Format::Obj: r.status = load_obj(bytes, &a); break;
    case Format::Off: r.status = load_off(bytes, &a); break;
    case Format::Ply: r.status = load_ply(bytes, &a); break;
    case Format::Gltf:
    case Format::Glb: r.status = load_gltf(bytes, format, resolver, opt, &a); break;
  }
  if (!r.status.ok()) {
    r.asset = Asset();
    r.asset.format = format;
    r.asset.source_name = name;
    return r;
  }
  if (format != Format::Gltf && format != Format::Glb) {
    PrimitiveRef p;
    p.num_vertices = static_cast<int>(a.V_raw.rows());
    p.num_faces = static_cast<int>(a.F_raw.rows());
    p.name = name;
    a.primitives.push_back(p);
  }
  a.weld = weld_vertices(a.V_raw, a.F_raw, opt.weld);
  return r;
}
}  // namespace detail

LoadResult load_asset_from_memory(const std::vector<uint8_t>& bytes, Format format, const std::string& name,
                                  const FileResolver& resolver, const LoadOptions& opt) {
  // The readers report data errors as Status; this net catches what only the allocator or a
  // library can throw (std::bad_alloc on a huge but consistent file), so nothing crosses the API.
  try {
    return detail::asset_load(bytes, format, name, resolver, opt);
  } catch (const std::bad_alloc&) {
    LoadResult r;
    r.asset.source_name = name;
    r.status = Status::error(StatusCode::IoError, name + ": out of memory while loading");
    return r;
  } catch (const std::exception& e) {
    LoadResult r;
    r.asset.source_name = name;
    r.status = Status::error(StatusCode::ParseError, name + ": " + e.what());
    return r;
  }
}

LoadResult load_asset(const std::string& path, const LoadOptions& opt) {
  LoadResult r;
  const std::optional<Format> format = format_from_path(path);
  if (!format) {
    r.status = Status::error(StatusCode::Unsupported,
                             "'" + path + "': unknown file extension (expected .gltf, .glb, .obj, .off or .ply)");
    return r;
  }
  std::vector<uint8_t> bytes;
  r.status = read_file(path, &bytes);
  if (!r.status.ok()) return r;
  // URIs reach the resolver only after load_gltf's safety check (relative, no "..", no scheme),
  // so joining them to the file's folder cannot leave it.
  const std::string dir = detail::asset_parent_dir(path);
  // The first refusal of a sibling file that exists (over kMaxInputBytes, not a regular file) is
  // kept: the loader only learns "not there", and the user must hear why.
  auto refused = std::make_shared<Status>();
  FileResolver resolver = [dir, refused](const std::string& uri, std::vector<uint8_t>* out) {
    Status s = read_file(dir + uri, out);
    if (!s.ok() && refused->ok() && s.message.find("no such file") == std::string::npos) *refused = s;
    return s.ok();
  };
  r = load_asset_from_memory(bytes, *format, path, resolver, opt);
  if (r.status.code == StatusCode::IoError && !refused->ok())
    r.status = Status::error(refused->code, path + ": " + refused->message);
  return r;
}

Status save_asset_to_memory(const Asset& asset, const Eigen::MatrixXd& V, Format format, std::vector<uint8_t>* bytes,
                            const SaveOptions& opt) {
  GltfFiles files;
  Status s = detail::asset_save(asset, V, format, opt, "", &files);
  if (s.ok()) *bytes = std::move(files.main);
  return s;
}

Status save_asset(const Asset& asset, const Eigen::MatrixXd& V, const std::string& path, const SaveOptions& opt) {
  const std::optional<Format> format = format_from_path(path);
  if (!format)
    return Status::error(StatusCode::Unsupported,
                         "'" + path + "': unknown file extension (expected .gltf, .glb, .obj, .off or .ply)");
  GltfFiles files;
  Status s = detail::asset_save(asset, V, *format, opt, *format == Format::Gltf ? detail::asset_stem(path) : "", &files);
  if (!s.ok()) return s;
  return detail::asset_write_files(path, files);
}

static Status asset_save_with_mesh(const Asset& asset, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                   Format format, const std::string& stem, GltfFiles* files) {
  Status s = detail::asset_check_mesh(V, F, {});
  if (!s.ok()) return s;
  const Document* doc = asset.document.get();
  try {
    if (doc && (doc->source_format == Format::Gltf || doc->source_format == Format::Glb) &&
        (format == Format::Gltf || format == Format::Glb))
      return save_gltf_with_mesh(asset, V, F, format, stem, files);
    ExportMesh m;
    m.V = V;
    m.F = F;
    return detail::asset_write_export(m, format, &files->main);
  } catch (const std::bad_alloc&) {
    return Status::error(StatusCode::IoError, "out of memory while saving");
  } catch (const std::exception& e) {
    return Status::error(StatusCode::IoError, std::string("saving failed: ") + e.what());
  }
}

Status save_asset_with_mesh_to_memory(const Asset& asset, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                      Format format, std::vector<uint8_t>* bytes) {
  GltfFiles files;
  Status s = asset_save_with_mesh(asset, V, F, format, "", &files);
  if (s.ok()) *bytes = std::move(files.main);
  return s;
}

Status save_asset_with_mesh(const Asset& asset, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                            const std::string& path) {
  const std::optional<Format> format = format_from_path(path);
  if (!format)
    return Status::error(StatusCode::Unsupported,
                         "'" + path + "': unknown file extension (expected .gltf, .glb, .obj, .off or .ply)");
  GltfFiles files;
  Status s = asset_save_with_mesh(asset, V, F, *format, *format == Format::Gltf ? detail::asset_stem(path) : "", &files);
  if (!s.ok()) return s;
  return detail::asset_write_files(path, files);
}

Status save_mesh_to_memory(Format format, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                           std::vector<uint8_t>* bytes, const Eigen::MatrixXd& colors) {
  Status s = detail::asset_check_mesh(V, F, colors);
  if (!s.ok()) return s;
  ExportMesh m;
  m.V = V;
  m.F = F.size() > 0 ? F : Eigen::MatrixXi(0, 3);
  m.C = colors;
  try {
    return detail::asset_write_export(m, format, bytes);
  } catch (const std::exception& e) {
    return Status::error(StatusCode::IoError, std::string("saving failed: ") + e.what());
  }
}

Status save_mesh(const std::string& path, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                 const Eigen::MatrixXd& colors) {
  const std::optional<Format> format = format_from_path(path);
  if (!format)
    return Status::error(StatusCode::Unsupported,
                         "'" + path + "': unknown file extension (expected .gltf, .glb, .obj, .off or .ply)");
  std::vector<uint8_t> bytes;
  Status s = save_mesh_to_memory(*format, V, F, &bytes, colors);
  if (!s.ok()) return s;
  return detail::asset_write_file(path, bytes);
}

}  // namespace mm::io
