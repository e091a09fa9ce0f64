// URIs inside glTF files: the path-traversal check and data-URI encoding (io-internal).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"

namespace mm::io {

// Percent-decodes a URI reference ("my%20file.bin" -> "my file.bin"). Invalid escapes are
// kept literally.
std::string uri_decode(const std::string& uri);

// True for "data:" URIs (case-insensitive scheme).
bool is_data_uri(const std::string& uri);

// Accepts a decoded external URI only when it names a file inside the glTF's own folder:
// relative, no ".." segment, no scheme ("http:", "file:", a drive letter), no leading slash or
// backslash, no NUL. Otherwise IoError naming `what` (e.g. "buffer 0") and the URI.
Status check_relative_uri(const std::string& decoded_uri, const std::string& what);

// Decodes a base64 data URI ("data:<mime>[;base64],<payload>"); false when malformed or not base64.
bool decode_data_uri(const std::string& uri, std::string* mime, std::vector<uint8_t>* bytes);
// "data:<mime>;base64,<payload>".
std::string encode_data_uri(const std::string& mime, const uint8_t* data, size_t size);

}  // namespace mm::io

namespace mm::io {
// Image MIME type from a file name's extension (png, jpg/jpeg, webp, ktx2); empty when unknown.
std::string image_mime_from_uri(const std::string& uri);
}  // namespace mm::io
