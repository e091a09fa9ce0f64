// Serialization of a tinygltf::Model to .gltf or .glb bytes (io-internal), with our buffer and
// image policy on top of tinygltf's writer.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"
#include "io/gltf_document.h"

namespace mm::io {

// A written glTF: the .gltf/.glb bytes and, for a .gltf written next to files, the external
// buffers and images it references (names relative to the .gltf, already URI-checked).
struct GltfFiles {
  std::vector<uint8_t> main;
  std::vector<std::pair<std::string, std::vector<uint8_t>>> sidecars;
};

// Glb: all buffers are merged into the BIN chunk and every image whose bytes are known
// (data URI or external file in image_files) is embedded as a bufferView.
// Gltf with a non-empty sidecar_stem: buffers go to "<stem>.bin" ("<stem>_<i>.bin" for
// further buffers), external images are passed through as sidecars under their own URI.
// Gltf with an empty stem: buffers become data URIs; external image URIs are kept as they are.
// Data-URI images stay data URIs in .gltf. image_files: per image, bytes of external files.
Status serialize_gltf(tinygltf::Model model, const std::vector<std::vector<uint8_t>>& image_files, Format target,
                      const std::string& sidecar_stem, GltfFiles* out);

}  // namespace mm::io
