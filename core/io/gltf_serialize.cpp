#include "io/gltf_serialize.h"

#include <sstream>

#include <nlohmann/json.hpp>

#include "io/gltf_builder.h"
#include "io/gltf_uri.h"

namespace mm::io {

namespace detail {

// Moves every buffer into buffer 0 (a GLB has one BIN chunk). Each old buffer starts on a
// 16-byte boundary so the alignment of its accessors is preserved.
static void gltf_merge_buffers(tinygltf::Model* m) {
  if (m->buffers.size() <= 1) {
    if (!m->buffers.empty()) m->buffers[0].uri.clear();
    return;
  }
  std::vector<size_t> base(m->buffers.size(), 0);
  std::vector<unsigned char>& merged = m->buffers[0].data;
  for (size_t i = 1; i < m->buffers.size(); ++i) {
    merged.resize((merged.size() + 15) / 16 * 16, 0);
    base[i] = merged.size();
    merged.insert(merged.end(), m->buffers[i].data.begin(), m->buffers[i].data.end());
  }
  for (tinygltf::BufferView& v : m->bufferViews) {
    if (v.buffer > 0 && v.buffer < static_cast<int>(base.size())) v.byteOffset += base[v.buffer];
    v.buffer = 0;
  }
  m->buffers.resize(1);
  m->buffers[0].uri.clear();
}

}  // namespace detail

Status serialize_gltf(tinygltf::Model m, const std::vector<std::vector<uint8_t>>& image_files, Format target,
                      const std::string& sidecar_stem, GltfFiles* out) {
  using namespace detail;
  out->main.clear();
  out->sidecars.clear();
  const bool glb = target == Format::Glb;
  if (glb) {
    if (m.buffers.empty()) m.buffers.emplace_back();
    gltf_merge_buffers(&m);
  }
  for (size_t i = 0; i < m.images.size(); ++i) {
    tinygltf::Image& im = m.images[i];
    if (im.bufferView >= 0) continue;
    const std::vector<uint8_t>* file = i < image_files.size() && !image_files[i].empty() ? &image_files[i] : nullptr;
    const bool from_data_uri = im.uri.empty() && !im.image.empty();
    if (glb && (from_data_uri || file)) {
      const std::string mime = !im.mimeType.empty() ? im.mimeType : image_mime_from_uri(uri_decode(im.uri));
      if (!mime.empty()) {
        const std::vector<unsigned char>& bytes = from_data_uri ? im.image : *file;
        im.bufferView = gltf_append_view(&m, 0, bytes.data(), bytes.size(), 0);
        im.mimeType = mime;
        im.uri.clear();
        im.image.clear();
        continue;
      }
    }
    if (from_data_uri) {
      im.uri = encode_data_uri(im.mimeType.empty() ? "application/octet-stream" : im.mimeType, im.image.data(),
                               im.image.size());
      im.image.clear();
    } else if (!glb && !sidecar_stem.empty() && file) {
      out->sidecars.emplace_back(uri_decode(im.uri), *file);
    }
  }
  // Sidecar buffers: serialize them empty, then put the file names and lengths into the JSON,
  // which avoids base64-encoding megabytes only to throw them away.
  std::vector<std::pair<std::string, size_t>> buffer_files;
  if (!glb && !sidecar_stem.empty()) {
    for (size_t i = 0; i < m.buffers.size(); ++i) {
      std::string name = sidecar_stem + (i == 0 ? "" : "_" + std::to_string(i)) + ".bin";
      buffer_files.emplace_back(name, m.buffers[i].data.size());
      out->sidecars.emplace_back(name, std::move(m.buffers[i].data));
      m.buffers[i].data.clear();
    }
  }
  std::ostringstream os;
  try {
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&m, os, /*prettyPrint=*/!glb, /*writeBinary=*/glb))
      return Status::error(StatusCode::IoError, "tinygltf could not serialize the glTF document");
    std::string text = os.str();
    if (!buffer_files.empty()) {
      nlohmann::json j = nlohmann::json::parse(text);
      for (size_t i = 0; i < buffer_files.size(); ++i) {
        j["buffers"][i]["uri"] = buffer_files[i].first;
        j["buffers"][i]["byteLength"] = buffer_files[i].second;
      }
      text = j.dump(2);
    }
    out->main.assign(text.begin(), text.end());
  } catch (const std::exception& e) {
    return Status::error(StatusCode::IoError, std::string("glTF serialization failed: ") + e.what());
  }
  return Status::success();
}

Status save_gltf_model_to_memory(const tinygltf::Model& model, Format format, std::vector<uint8_t>* bytes) {
  GltfFiles files;
  Status s;
  try {
    s = serialize_gltf(model, {}, format, "", &files);
  } catch (const std::exception& e) {
    s = Status::error(StatusCode::IoError, std::string("glTF serialization failed: ") + e.what());
  }
  if (s.ok()) *bytes = std::move(files.main);
  return s;
}

}  // namespace mm::io
