// Landmark files: {"pairs": [[reference_vertex, source_vertex], ...]} (plus free-form fields such
// as "comment"), as kept in data/landmarks/. Read by the CLI and the tests.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "common/status.h"
#include "mesh/correspondence.h"

namespace mm::io {

// ParseError names the file and the first malformed pair; IoError when unreadable.
Status read_landmarks(const std::string& path, std::vector<LandmarkPair>* pairs);

// The same from the file's text (`name` is used in messages only). `pairs` is left empty on error.
Status parse_landmarks(std::string_view text, const std::string& name, std::vector<LandmarkPair>* pairs);

}  // namespace mm::io
