#include "io/gltf_load.h"

#include <algorithm>
#include <cmath>

#include <cstring>
#include <map>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "io/gltf_accessor.h"
#include "io/gltf_document.h"
#include "io/gltf_uri.h"
#include "io/json_text.h"

namespace mm::io {

// The rest pose of a skinned primitive (glTF 2.0 §3.7.3, skins): per vertex the affine map
// A_v = Σ_k w_k · world(joint_k) · inverseBind_k, row-major 3×4 rows of *A. False (with *why set
// when the file is at fault) when the primitive has no JOINTS_0/WEIGHTS_0, a joint lies outside
// the scene, or an accessor is unreadable.
static bool gltf_rest_skin(const tinygltf::Model& m, const tinygltf::Primitive& prim, int skin_index,
                           const std::vector<Eigen::Matrix4d>& world, const std::vector<char>& placed, Eigen::Index nv,
                           Eigen::MatrixXd* A, std::string* why) {
  if (skin_index < 0 || skin_index >= static_cast<int>(m.skins.size())) return false;
  const tinygltf::Skin& skin = m.skins[skin_index];
  const int nj = static_cast<int>(skin.joints.size());
  if (nj == 0) return false;
  Matrix4dList M;
  if (!read_gltf_inverse_binds(m, skin, &M)) {
    *why = "its skin's inverseBindMatrices are unreadable";
    return false;
  }
  for (int j = 0; j < nj; ++j) {
    const int node = skin.joints[j];
    if (node < 0 || node >= static_cast<int>(world.size()) || !placed[node]) return false;
    M[j] = world[node] * M[j];
  }
  Eigen::MatrixXd J, W;
  if (!read_gltf_skin_influences(m, prim, nv, &J, &W)) {
    *why = "its JOINTS/WEIGHTS are unreadable";
    return false;
  }
  if (J.cols() == 0) return false;
  A->setZero(nv, 12);
  Eigen::VectorXd total = Eigen::VectorXd::Zero(nv);
  for (Eigen::Index v = 0; v < nv; ++v)
    for (Eigen::Index k = 0; k < J.cols(); ++k) {
      const double w = W(v, k);
      if (!(w > 0)) continue;
      const double jf = J(v, k);
      if (!(jf >= 0 && jf < nj)) {
        *why = "a vertex names joint " + std::to_string(static_cast<long long>(jf)) + " of a skin with " + std::to_string(nj);
        return false;
      }
      const Eigen::Matrix4d& Mj = M[static_cast<int>(jf)];
      for (int r = 0; r < 3; ++r) A->row(v).segment<4>(4 * r) += w * Mj.row(r);
      total[v] += w;
    }
  for (Eigen::Index v = 0; v < nv; ++v) {
    if (!(total[v] > 0)) return false;  // a vertex no joint moves: leave the primitive in its bind pose
    A->row(v) /= total[v];
  }
  return A->allFinite();
}

const tinygltf::Model* gltf_model(const Asset& asset) {
  const Document* d = asset.document.get();
  if (!d || (d->source_format != Format::Gltf && d->source_format != Format::Glb)) return nullptr;
  return &static_cast<const GltfDocument*>(d)->model;
}

std::shared_ptr<Document> make_gltf_document(tinygltf::Model model) {
  auto doc = std::make_shared<GltfDocument>();
  doc->model = std::move(model);
  doc->image_files.resize(doc->model.images.size());
  return doc;
}

namespace detail {

// External files read before tinygltf parses, served to it through FsCallbacks so that the
// same code runs natively (files next to the .gltf) and in the browser (files the user dropped).
struct GltfFsContext {
  std::map<std::string, std::vector<uint8_t>> files;  // decoded URI -> bytes
};

static std::string gltf_fs_key(const std::string& path) {
  // tinygltf tries "<basedir>/<uri>" with an empty basedir (the URI itself) and then "./<uri>".
  return path.compare(0, 2, "./") == 0 ? path.substr(2) : path;
}

static bool gltf_fs_exists(const std::string& path, void* user) {
  const auto* ctx = static_cast<GltfFsContext*>(user);
  return ctx->files.count(gltf_fs_key(path)) > 0;
}

static std::string gltf_fs_expand(const std::string& path, void*) { return path; }

static bool gltf_fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const auto* ctx = static_cast<GltfFsContext*>(user);
  const auto it = ctx->files.find(gltf_fs_key(path));
  if (it == ctx->files.end()) {
    if (err) *err += "not available: " + path;
    return false;
  }
  out->assign(it->second.begin(), it->second.end());
  return true;
}

static bool gltf_fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is not allowed while loading";
  return false;
}

// Images are never decoded: the encoded bytes (PNG, JPEG, KTX2, ...) are kept so that saving
// writes them back unchanged. bufferView images stay in their buffer.
static bool gltf_keep_image_bytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                                  const unsigned char* bytes, int size, void*) {
  image->as_is = true;
  if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
  return true;
}

static uint32_t gltf_read_u32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// Checks the GLB container (which tinygltf trusts) and returns its JSON chunk.
static Status gltf_glb_json(const std::vector<uint8_t>& b, const std::string& name, std::string* json,
                            uint64_t* bin_size) {
  auto fail = [&](StatusCode c, const std::string& why) { return Status::error(c, name + ": " + why); };
  if (b.size() < 12) return fail(StatusCode::ParseError, "truncated GLB: " + std::to_string(b.size()) +
                                                              " bytes, less than the 12-byte header");
  if (std::memcmp(b.data(), "glTF", 4) != 0) {
    const bool looks_json = b[0] == '{' || b[0] == ' ' || b[0] == '\n';
    return fail(StatusCode::ParseError, std::string("not a GLB file (no 'glTF' magic)") +
                                            (looks_json ? "; it looks like a .gltf JSON file, rename it to .gltf" : ""));
  }
  const uint32_t version = gltf_read_u32(&b[4]), length = gltf_read_u32(&b[8]);
  if (version != 2)
    return fail(StatusCode::Unsupported, "GLB version " + std::to_string(version) + " (only glTF 2.0 is supported)");
  if (length > b.size())
    return fail(StatusCode::ParseError, "truncated GLB: the header declares " + std::to_string(length) +
                                            " bytes but the file has " + std::to_string(b.size()));
  if (length < 20) return fail(StatusCode::ParseError, "truncated GLB: no JSON chunk");
  const uint32_t json_len = gltf_read_u32(&b[12]), json_type = gltf_read_u32(&b[16]);
  if (json_type != 0x4E4F534A) return fail(StatusCode::ParseError, "the first GLB chunk is not JSON");
  if (uint64_t(20) + json_len > length)
    return fail(StatusCode::ParseError, "truncated GLB: the JSON chunk (" + std::to_string(json_len) +
                                            " bytes) runs past the end of the file");
  json->assign(reinterpret_cast<const char*>(&b[20]), json_len);
  *bin_size = 0;
  const uint64_t bin_at = 20 + uint64_t(json_len);
  if (bin_at + 8 <= length) {
    const uint32_t bin_len = gltf_read_u32(&b[bin_at]), bin_type = gltf_read_u32(&b[bin_at + 4]);
    if (bin_type == 0x004E4942) {
      if (bin_at + 8 + bin_len > length)
        return fail(StatusCode::ParseError, "truncated GLB: the BIN chunk declares " + std::to_string(bin_len) +
                                                " bytes but only " + std::to_string(length - bin_at - 8) + " follow");
      *bin_size = bin_len;
    }
  }
  return Status::success();
}

// Non-negative integer field `key` of `o`, or `fallback` when absent. A present value that is
// negative, fractional, too large or not a number sets *bad (the caller names the field).
static uint64_t gltf_json_uint(const nlohmann::json& o, const char* key, uint64_t fallback, bool* bad) {
  const auto it = o.find(key);
  if (it == o.end()) return fallback;
  if (it->is_number_unsigned()) return it->get<uint64_t>();
  if (it->is_number_integer() && it->get<int64_t>() >= 0) return static_cast<uint64_t>(it->get<int64_t>());
  *bad = true;
  return fallback;
}

// offset + length ≤ size without wrapping around.
static bool gltf_range_fits(uint64_t offset, uint64_t length, uint64_t size) {
  return offset <= size && length <= size - offset;
}

// What tinygltf does not check before touching memory (image bufferViews are read during
// parsing) plus the URI policy; also reads external files through the resolver.
static Status gltf_precheck(const nlohmann::json& j, bool binary, uint64_t bin_size, const std::string& name,
                            const FileResolver& resolver, GltfFsContext* fs,
                            std::vector<std::vector<uint8_t>>* image_files, std::vector<std::string>* warnings) {
  auto fail = [&](StatusCode c, const std::string& why) { return Status::error(c, name + ": " + why); };
  if (!j.is_object()) return fail(StatusCode::ParseError, "glTF JSON must be an object");
  const auto asset_it = j.find("asset");
  if (asset_it != j.end() && asset_it->is_object()) {
    const auto v = asset_it->find("version");
    if (v != asset_it->end() && v->is_string() && v->get<std::string>().rfind("2.", 0) != 0)
      return fail(StatusCode::Unsupported, "glTF version " + v->get<std::string>() + " (only glTF 2.0 is supported)");
  }
  std::vector<uint64_t> buffer_len;
  const auto buffers = j.find("buffers");
  if (buffers != j.end() && buffers->is_array()) {
    for (size_t i = 0; i < buffers->size(); ++i) {
      const nlohmann::json& b = (*buffers)[i];
      if (!b.is_object()) return fail(StatusCode::ParseError, "buffer " + std::to_string(i) + " is not an object");
      bool bad = false;
      buffer_len.push_back(gltf_json_uint(b, "byteLength", 0, &bad));
      if (bad) return fail(StatusCode::ParseError, "buffer " + std::to_string(i) + " has an invalid byteLength (not a non-negative integer)");
      const auto uri_it = b.find("uri");
      if (uri_it == b.end() || !uri_it->is_string()) {
        if (!(binary && i == 0))
          return fail(StatusCode::ParseError, "buffer " + std::to_string(i) + " has no uri");
        if (buffer_len.back() > bin_size)
          return fail(StatusCode::ParseError, "buffer 0 declares " + std::to_string(buffer_len.back()) +
                                                  " bytes but the GLB BIN chunk has " + std::to_string(bin_size));
        continue;
      }
      const std::string uri = uri_it->get<std::string>();
      if (is_data_uri(uri)) continue;
      const std::string decoded = uri_decode(uri);
      Status s = check_relative_uri(decoded, name + ": buffer " + std::to_string(i));
      if (!s.ok()) return s;
      std::vector<uint8_t> bytes;
      if (!resolver || !resolver(decoded, &bytes))
        return fail(StatusCode::IoError, "buffer " + std::to_string(i) + " refers to the missing file '" + quote_input(decoded) +
                                             "' (it must be next to the .gltf file)");
      if (bytes.size() < buffer_len.back())
        return fail(StatusCode::ParseError, "'" + quote_input(decoded) + "' has " + std::to_string(bytes.size()) +
                                                " bytes but buffer " + std::to_string(i) + " declares " +
                                                std::to_string(buffer_len.back()));
      // The glTF spec allows a file longer than byteLength (padding); tinygltf wants exact.
      bytes.resize(buffer_len.back());
      fs->files[decoded] = std::move(bytes);
    }
  }
  std::vector<std::pair<uint64_t, uint64_t>> views;  // buffer, end offset
  const auto bvs = j.find("bufferViews");
  if (bvs != j.end() && bvs->is_array()) {
    for (size_t i = 0; i < bvs->size(); ++i) {
      const nlohmann::json& v = (*bvs)[i];
      if (!v.is_object()) return fail(StatusCode::ParseError, "bufferView " + std::to_string(i) + " is not an object");
      bool bad = false;
      const uint64_t buf = gltf_json_uint(v, "buffer", UINT64_MAX, &bad);
      const uint64_t offset = gltf_json_uint(v, "byteOffset", 0, &bad), length = gltf_json_uint(v, "byteLength", 0, &bad);
      const uint64_t stride = gltf_json_uint(v, "byteStride", 0, &bad);
      if (bad)
        return fail(StatusCode::ParseError, "bufferView " + std::to_string(i) +
                                                " has a buffer, byteOffset, byteLength or byteStride that is not a non-negative integer");
      if (buf >= buffer_len.size())
        return fail(StatusCode::ParseError, "bufferView " + std::to_string(i) + " refers to a missing buffer");
      if (!gltf_range_fits(offset, length, buffer_len[buf]))
        return fail(StatusCode::ParseError, "bufferView " + std::to_string(i) + " (offset " + std::to_string(offset) +
                                                ", length " + std::to_string(length) + ") lies outside buffer " +
                                                std::to_string(buf) + " (" + std::to_string(buffer_len[buf]) + " bytes)");
      if (stride != 0 && (stride < 4 || stride > 252))
        return fail(StatusCode::ParseError, "bufferView " + std::to_string(i) + " has byteStride " + std::to_string(stride) +
                                                " (glTF allows 4 to 252)");
      views.emplace_back(buf, offset + length);
    }
  }
  const auto accessors = j.find("accessors");
  if (accessors != j.end() && accessors->is_array()) {
    for (size_t i = 0; i < accessors->size(); ++i) {
      const nlohmann::json& a = (*accessors)[i];
      if (!a.is_object()) return fail(StatusCode::ParseError, "accessor " + std::to_string(i) + " is not an object");
      bool bad = false;
      const uint64_t view = gltf_json_uint(a, "bufferView", UINT64_MAX, &bad);
      gltf_json_uint(a, "byteOffset", 0, &bad);
      gltf_json_uint(a, "count", 0, &bad);
      if (bad)
        return fail(StatusCode::ParseError, "accessor " + std::to_string(i) +
                                                " has a bufferView, byteOffset or count that is not a non-negative integer");
      if (a.contains("bufferView") && view >= views.size())
        return fail(StatusCode::ParseError, "accessor " + std::to_string(i) + " refers to a missing bufferView");
    }
  }
  // Skins and animations reference nodes and samplers by index; tinygltf does not check them.
  const auto nodes = j.find("nodes");
  const uint64_t num_nodes = nodes != j.end() && nodes->is_array() ? nodes->size() : 0;
  const auto skins = j.find("skins");
  if (skins != j.end() && skins->is_array()) {
    for (size_t i = 0; i < skins->size(); ++i) {
      const nlohmann::json& sk = (*skins)[i];
      const auto jt = sk.is_object() ? sk.find("joints") : sk.end();
      if (!sk.is_object() || jt == sk.end() || !jt->is_array())
        return fail(StatusCode::ParseError, "skin " + std::to_string(i) + " has no joints array");
      for (size_t k = 0; k < jt->size(); ++k) {
        const nlohmann::json& n = (*jt)[k];
        if (!n.is_number_integer() || n.get<int64_t>() < 0 || static_cast<uint64_t>(n.get<int64_t>()) >= num_nodes)
          return fail(StatusCode::ParseError, "skin " + std::to_string(i) + " joint " + std::to_string(k) +
                                                  " is not one of the " + std::to_string(num_nodes) + " nodes");
      }
    }
  }
  const auto animations = j.find("animations");
  if (animations != j.end() && animations->is_array()) {
    for (size_t i = 0; i < animations->size(); ++i) {
      const nlohmann::json& an = (*animations)[i];
      if (!an.is_object()) return fail(StatusCode::ParseError, "animation " + std::to_string(i) + " is not an object");
      const auto samplers = an.find("samplers");
      const uint64_t num_samplers = samplers != an.end() && samplers->is_array() ? samplers->size() : 0;
      const auto channels = an.find("channels");
      if (channels == an.end() || !channels->is_array()) continue;
      for (size_t k = 0; k < channels->size(); ++k) {
        const nlohmann::json& ch = (*channels)[k];
        bool bad = !ch.is_object();
        const uint64_t sampler = bad ? 0 : gltf_json_uint(ch, "sampler", UINT64_MAX, &bad);
        const auto target = bad ? ch.end() : ch.find("target");
        uint64_t node = 0;
        if (!bad && target != ch.end() && target->is_object()) node = gltf_json_uint(*target, "node", 0, &bad);
        if (bad || sampler >= num_samplers || (target != ch.end() && target->is_object() && target->contains("node") &&
                                               node >= num_nodes))
          return fail(StatusCode::ParseError, "animation " + std::to_string(i) + " channel " + std::to_string(k) +
                                                  " refers to a missing sampler or node");
      }
    }
  }
  const auto images = j.find("images");
  if (images != j.end() && images->is_array()) {
    image_files->resize(images->size());
    for (size_t i = 0; i < images->size(); ++i) {
      const nlohmann::json& im = (*images)[i];
      if (!im.is_object()) return fail(StatusCode::ParseError, "image " + std::to_string(i) + " is not an object");
      if (im.contains("bufferView")) {
        bool bad = false;
        if (gltf_json_uint(im, "bufferView", UINT64_MAX, &bad) >= views.size() || bad)
          return fail(StatusCode::ParseError, "image " + std::to_string(i) + " refers to a missing bufferView");
        continue;
      }
      const auto uri_it = im.find("uri");
      if (uri_it == im.end() || !uri_it->is_string()) continue;  // tinygltf reports it
      const std::string uri = uri_it->get<std::string>();
      if (is_data_uri(uri)) continue;
      const std::string decoded = uri_decode(uri);
      Status s = check_relative_uri(decoded, name + ": image " + std::to_string(i));
      if (!s.ok()) return s;
      if (!resolver || !resolver(decoded, &(*image_files)[i]))
        warnings->push_back("image " + std::to_string(i) + " ('" + quote_input(decoded) +
                            "') was not found; its URI is kept but the image cannot be embedded on export");
    }
  }
  return Status::success();
}

// Local transform of a node: its matrix, or T * R * S.
static Eigen::Matrix4d gltf_node_local(const tinygltf::Node& n) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  if (n.matrix.size() == 16) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) M(r, c) = n.matrix[c * 4 + r];  // column-major in glTF
    return M;
  }
  Eigen::Affine3d T = Eigen::Affine3d::Identity();
  if (n.translation.size() == 3) T.translate(Eigen::Vector3d(n.translation[0], n.translation[1], n.translation[2]));
  if (n.rotation.size() == 4)
    T.rotate(Eigen::Quaterniond(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]).normalized());
  if (n.scale.size() == 3) T.scale(Eigen::Vector3d(n.scale[0], n.scale[1], n.scale[2]));
  return T.matrix();
}

static const char* gltf_mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    case TINYGLTF_MODE_TRIANGLE_STRIP: return "TRIANGLE_STRIP";
    case TINYGLTF_MODE_TRIANGLE_FAN: return "TRIANGLE_FAN";
  }
  return "unknown";
}

}  // namespace detail

Status load_gltf(const std::vector<uint8_t>& bytes, Format format, const FileResolver& resolver,
                 const LoadOptions& opt, Asset* asset) {
  using namespace detail;
  const std::string& name = asset->source_name;
  // Trust the content over the extension: a .gltf that is really a GLB (or the reverse)
  // loads as what it is.
  bool binary = format == Format::Glb;
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) binary = true;
  else if (binary && !bytes.empty() && (bytes[0] == '{' || (bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB)))
    binary = false;
  asset->format = binary ? Format::Glb : Format::Gltf;
  std::string json_text;
  uint64_t bin_size = 0;
  if (binary) {
    Status s = gltf_glb_json(bytes, name, &json_text, &bin_size);
    if (!s.ok()) return s;
  } else {
    // A UTF-8 byte order mark is not JSON, but some editors write one.
    const size_t skip = bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB && bytes[2] == 0xBF ? 3 : 0;
    json_text.assign(bytes.begin() + skip, bytes.end());
  }
  // Depth first: tinygltf walks values (extras, extensions) recursively.
  if (Status d = check_json_depth(json_text, name); !d.ok()) return d;
  auto doc = std::make_shared<GltfDocument>();
  GltfFsContext fs;
  try {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(json_text);
    } catch (const nlohmann::json::exception& e) {
      return Status::error(StatusCode::ParseError, name + ": invalid glTF JSON: " + cap_message(e.what()));
    }
    Status s = gltf_precheck(j, binary, bin_size, name, resolver, &fs, &doc->image_files, &asset->warnings);
    if (!s.ok()) return s;
  } catch (const std::exception& e) {
    return Status::error(StatusCode::ParseError, name + ": malformed glTF: " + cap_message(e.what()));
  }

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&gltf_keep_image_bytes, nullptr);
  loader.SetFsCallbacks({&gltf_fs_exists, &gltf_fs_expand, &gltf_fs_read, &gltf_fs_write, &fs});
  tinygltf::Model& model = doc->model;
  std::string err, warn;
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), static_cast<unsigned>(bytes.size()), "")
                : loader.LoadASCIIFromString(&model, &err, &warn, json_text.c_str(),
                                             static_cast<unsigned>(json_text.size()), "");
  } catch (const std::exception& e) {
    ok = false;
    err += e.what();
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    return Status::error(StatusCode::ParseError, name + ": invalid glTF: " + (err.empty() ? "unknown error" : cap_message(err)));
  }
  if (!warn.empty()) asset->warnings.push_back(cap_message(warn));
  for (size_t a = 0; a < model.animations.size(); ++a)
    for (size_t k = 0; k < model.animations[a].samplers.size(); ++k) {
      Eigen::MatrixXd t;
      const std::string where = name + ": animation " + std::to_string(a) + " sampler " + std::to_string(k);
      if (Status s = read_gltf_accessor(model, model.animations[a].samplers[k].input, &t); !s.ok())
        return Status::error(s.code, where + " input: " + s.message);
      for (Eigen::Index i = 0; i < t.rows(); ++i)
        if (!std::isfinite(t(i, 0)) || (i > 0 && !(t(i, 0) > t(i - 1, 0))))
          return Status::error(StatusCode::ParseError, where + ": input times must be finite and strictly increasing (key " +
                                                           std::to_string(i) + ")");
    }
  for (const std::string& ext : model.extensionsRequired)
    if (ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression")
      return Status::error(StatusCode::Unsupported, name + ": the file requires the extension " + ext +
                                                        " (compressed geometry); export it without compression");
  doc->image_files.resize(model.images.size());

  // Roots: the default scene, scene 0, or (no scenes) every node that is nobody's child.
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const int scene = model.defaultScene >= 0 && model.defaultScene < static_cast<int>(model.scenes.size())
                          ? model.defaultScene
                          : 0;
    roots = model.scenes[scene].nodes;
  } else {
    std::vector<char> is_child(model.nodes.size(), 0);
    for (const tinygltf::Node& n : model.nodes)
      for (int c : n.children)
        if (c >= 0 && c < static_cast<int>(model.nodes.size())) is_child[c] = 1;
    for (size_t i = 0; i < model.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }

  std::vector<Eigen::RowVector3d> positions;
  std::vector<Eigen::RowVector3i> triangles;
  std::vector<char> visited(model.nodes.size(), 0);
  std::vector<Eigen::Matrix4d> node_world(model.nodes.size(), Eigen::Matrix4d::Identity());
  std::vector<std::pair<size_t, Eigen::MatrixXd>> skinned_local;  // (primitive ref, mesh-space positions)
  // Depth-first in scene order; an explicit stack keeps deep hierarchies off the call stack.
  struct Item { int node; Eigen::Matrix4d parent; };
  std::vector<Item> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, Eigen::Matrix4d::Identity()});
  int skipped = 0;
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    if (item.node < 0 || item.node >= static_cast<int>(model.nodes.size()))
      return Status::error(StatusCode::ParseError, name + ": node " + std::to_string(item.node) + " does not exist");
    if (visited[item.node])
      return Status::error(StatusCode::ParseError, name + ": node " + std::to_string(item.node) +
                                                       " is reached twice (the node hierarchy must be a tree)");
    visited[item.node] = 1;
    const tinygltf::Node& node = model.nodes[item.node];
    const Eigen::Matrix4d world = item.parent * gltf_node_local(node);
    node_world[item.node] = world;
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back({*c, world});
    if (node.mesh < 0) continue;
    if (node.mesh >= static_cast<int>(model.meshes.size()))
      return Status::error(StatusCode::ParseError, name + ": node " + std::to_string(item.node) +
                                                       " refers to missing mesh " + std::to_string(node.mesh));
    const tinygltf::Mesh& mesh = model.meshes[node.mesh];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      const std::string label = "mesh " + std::to_string(node.mesh) + (mesh.name.empty() ? "" : " ('" + mesh.name + "')") +
                                " primitive " + std::to_string(pi);
      if (!gltf_is_triangle_mode(prim.mode)) {
        if (!opt.skip_unsupported_primitives)
          return Status::error(StatusCode::Unsupported,
                               name + ": " + label + " uses mode " + gltf_mode_name(prim.mode) +
                                   "; only triangle primitives (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) are "
                                   "supported (load with skip_unsupported_primitives to ignore it)");
        ++skipped;
        continue;
      }
      if (prim.attributes.find("POSITION") == prim.attributes.end()) {
        asset->warnings.push_back(label + " has no POSITION attribute and was skipped");
        continue;
      }
      GltfTriangles tris;
      if (Status s = read_gltf_triangles(model, prim, label, &tris); !s.ok())
        return Status::error(s.code, name + ": " + s.message);
      const Eigen::MatrixXd& P = tris.P;
      const int nv = static_cast<int>(P.rows());
      PrimitiveRef ref;
      ref.node = item.node;
      ref.mesh = node.mesh;
      ref.primitive = static_cast<int>(pi);
      ref.first_vertex = static_cast<int>(positions.size());
      ref.num_vertices = nv;
      ref.first_face = static_cast<int>(triangles.size());
      ref.num_faces = static_cast<int>(tris.F.rows());
      ref.skinned = node.skin >= 0;
      ref.world = world;
      ref.name = node.name + "/" + mesh.name + "#" + std::to_string(pi);
      for (int v = 0; v < nv; ++v) {
        const Eigen::Vector4d p = world * Eigen::Vector4d(P(v, 0), P(v, 1), P(v, 2), 1.0);
        positions.emplace_back(p.x(), p.y(), p.z());
      }
      for (int f = 0; f < ref.num_faces; ++f)
        triangles.emplace_back(ref.first_vertex + tris.F(f, 0), ref.first_vertex + tris.F(f, 1),
                               ref.first_vertex + tris.F(f, 2));
      if (ref.skinned) skinned_local.emplace_back(asset->primitives.size(), P);
      asset->primitives.push_back(ref);
    }
  }
  // Skinned primitives in their rest pose where it differs from the bind pose (asset.h).
  for (const auto& [index, P] : skinned_local) {
    PrimitiveRef& ref = asset->primitives[index];
    Eigen::MatrixXd A;
    std::string why;
    if (!gltf_rest_skin(model, model.meshes[ref.mesh].primitives[ref.primitive], model.nodes[ref.node].skin, node_world,
                        visited, P.rows(), &A, &why)) {
      if (!why.empty()) asset->warnings.push_back(ref.name + ": " + why + "; the bind pose is used");
      continue;
    }
    Eigen::AlignedBox3d box;
    double moved = 0;
    Eigen::MatrixXd R(P.rows(), 3);
    for (Eigen::Index v = 0; v < P.rows(); ++v) {
      const Eigen::Vector3d b = positions[ref.first_vertex + v].transpose();
      R.row(v) = (rest_skin_map(A, v) * P.row(v).transpose().homogeneous()).transpose();
      box.extend(b);
      moved = std::max(moved, (R.row(v).transpose() - b).norm());
    }
    // Bind pose = rest pose up to the inverse bind matrices' float rounding (every character in
    // data/ but the robot's hands: at most 2.7e-6 of the primitive's size; those hands 1.5–1.7
    // sizes): keep the exact bind pose below 1e-3 of the size.
    if (!(moved > 1e-3 * std::max(box.diagonal().norm(), 1e-12)) || !R.allFinite()) continue;
    for (Eigen::Index v = 0; v < P.rows(); ++v) positions[ref.first_vertex + v] = R.row(v);
    ref.rest_skin = std::move(A);
  }
  if (skipped > 0)
    asset->warnings.push_back(std::to_string(skipped) + " non-triangle primitive(s) were skipped and are kept unchanged");
  if (asset->primitives.empty())
    return Status::error(StatusCode::InvalidMesh, name + ": the scene has no triangle mesh primitives");
  asset->V_raw.resize(static_cast<Eigen::Index>(positions.size()), 3);
  for (size_t i = 0; i < positions.size(); ++i) asset->V_raw.row(static_cast<Eigen::Index>(i)) = positions[i];
  asset->F_raw.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (size_t i = 0; i < triangles.size(); ++i) asset->F_raw.row(static_cast<Eigen::Index>(i)) = triangles[i];
  asset->document = std::move(doc);
  return Status::success();
}

}  // namespace mm::io
