// glTF 2.0 reader (io-internal; the public entry points are in io/asset.h, whose header
// comment states what is loaded).
#pragma once

#include <cstdint>
#include <vector>

#include "common/status.h"
#include "io/asset.h"

namespace mm::io {

// Parses .gltf (format Gltf) or .glb (format Glb) bytes; external buffers and images are read
// through `resolver` after the URI safety check (gltf_uri.h). Fills asset->V_raw, F_raw,
// primitives, warnings and document.
Status load_gltf(const std::vector<uint8_t>& bytes, Format format, const FileResolver& resolver,
                 const LoadOptions& opt, Asset* asset);

}  // namespace mm::io
