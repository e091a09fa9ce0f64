// Landmark files: {"pairs": [[reference_vertex, source_vertex], ...]} (plus free-form fields such
// as "comment"), as kept in data/landmarks/. Read by the CLI and the tests.
#pragma once

#include <string>
#include <vector>

#include "common/status.h"
#include "mesh/correspondence.h"

namespace mm::io {

// ParseError names the file and the first malformed pair; IoError when unreadable.
Status read_landmarks(const std::string& path, std::vector<LandmarkPair>* pairs);

}  // namespace mm::io
