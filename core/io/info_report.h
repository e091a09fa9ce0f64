// The `meshmorph info` report of a loaded asset, as text and JSON. The CLI prints it, the
// wasm binding hands the JSON to the page's info panel, so both show the same facts.
#pragma once

#include <string>

#include "io/asset.h"
#include "mesh/validate.h"

namespace mm::io {

struct InfoReport {
  MeshReport welded;   // validation of the welded geometry mesh (what algorithms see)
  MeshReport raw;      // validation of the raw layout (glTF: seam-split vertices)
  std::string text;    // human-readable, multi-line
  std::string json;    // one JSON object (schema: see info_report.cpp)
};

InfoReport info_report(const Asset& asset);

}  // namespace mm::io
