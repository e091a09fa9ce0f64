// glTF document access for code inside core/io (and the retarget export, which needs the
// skins and animations): the tinygltf::Model an Asset loaded from .gltf/.glb.
//
// Include this header only from targets that link mm::tinygltf (or from core/io). The
// TINYGLTF_NO_* macros below must match the implementation TU (core/io/tinygltf_impl.cpp);
// they are repeated here so that a TU that forgets the target's definitions still links.
#pragma once

#ifndef TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE
#endif
#ifndef TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#endif
#ifndef TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#endif

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "io/asset.h"
#include "io/document.h"

namespace mm::io {

// The glTF Document. Images keep their encoded bytes: bufferView images live in their buffer
// (untouched), data-URI images are decoded into Image::image with as_is = true, and the bytes
// of external-URI images (read through the FileResolver) are kept in image_files so that
// conversion to GLB can embed them and saving a .gltf elsewhere can copy them.
class GltfDocument : public Document {
 public:
  GltfDocument() : Document(Format::Gltf) {}
  tinygltf::Model model;
  std::vector<std::vector<uint8_t>> image_files;  // per image; empty unless an external URI was read
};

// The model of a glTF/GLB asset, nullptr when the asset came from another format.
const tinygltf::Model* gltf_model(const Asset& asset);

// A Document holding `model` (for an Asset built or modified inside core/io, e.g. an
// animation export). Images are taken as they are in the model.
std::shared_ptr<Document> make_gltf_document(tinygltf::Model model);

// Writes a model as .glb (one BIN chunk) or .gltf (buffers as data URIs) bytes with the same
// buffer and image policy as save_asset (see gltf_serialize.h). IoError when serialization fails.
Status save_gltf_model_to_memory(const tinygltf::Model& model, Format format, std::vector<uint8_t>* bytes);

}  // namespace mm::io
