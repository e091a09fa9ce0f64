// Part-pair files for hierarchical pose transfer (`meshmorph transfer --parts P.json`, written
// by `--parts-out`):
//   {"parts": [{"name": "left arm",
//               "source":    {"disk": {"seed": 812, "radius": 0.12}},
//               "reference": {"plane": {"point": [x,y,z], "normal": [x,y,z], "keep": [x,y,z]}},
//               "children": [ ...same form... ]}]}
// A region is one of {"disk": {"seed", "radius"}} (radius: fraction of the bbox diagonal),
// {"plane": {"point", "normal", "keep"}} or {"vertices": [...]}. "reference" may be omitted when
// both meshes have the same connectivity: it is then the source's region. Free-form fields
// (e.g. "comment", "score") are ignored. See mesh/part_spec.h.
#pragma once

#include <string>
#include <string_view>

#include "common/status.h"
#include "mesh/part_spec.h"

namespace mm::io {

// ParseError names the file and the part (by its path of indices, "parts[1].children[0]").
Status parse_parts(std::string_view text, const std::string& name, PartsSpec* spec);
Status read_parts(const std::string& path, PartsSpec* spec);

// JSON text of `spec` (both regions written), deterministic; `comment` goes to a top-level field.
std::string parts_json(const PartsSpec& spec, const std::string& comment = "");
Status write_parts(const std::string& path, const PartsSpec& spec, const std::string& comment = "");

}  // namespace mm::io
