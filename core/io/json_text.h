// Guards for JSON text from users (glTF, edit specs, landmark, joint and joint-map files), applied
// before any parser or recursive walk sees it, and for quoting user input in error messages.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "common/status.h"

namespace mm::io {

// Deepest nesting of arrays/objects any of our JSON documents needs is < 20; 256 leaves room and
// keeps recursive walkers (tinygltf's extras, nlohmann's value tree) far from the stack limit.
constexpr int kMaxJsonDepth = 256;

// ParseError "<what>: JSON nested deeper than 256 levels (at byte N)" when arrays/objects nest
// deeper than max_depth (strings and escapes are skipped correctly); success otherwise. Linear,
// no allocation; does not validate the rest of the syntax (the parser does).
Status check_json_depth(std::string_view text, const std::string& what, int max_depth = kMaxJsonDepth);

// At most `max` bytes of user input for a message: the text itself when short, otherwise its start
// followed by "... (N bytes)". Control characters are shown as '?'.
std::string quote_input(std::string_view text, size_t max = 100);

// A message from a third-party parser that may echo the input (nlohmann's "last read: '...'",
// tinygltf's URIs): cut to `max` bytes with "... (cut)" so that an error is never megabytes long.
std::string cap_message(std::string message, size_t max = 400);

}  // namespace mm::io
