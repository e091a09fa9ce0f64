#include "io/gltf_uri.h"
#include "io/json_text.h"

#include <cctype>

namespace mm::io {

namespace detail {

static int uri_hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

static int uri_base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') return 62;  // '-' and '_': the URL-safe alphabet some writers use
  if (c == '/' || c == '_') return 63;
  return -1;
}

}  // namespace detail

std::string uri_decode(const std::string& uri) {
  std::string out;
  out.reserve(uri.size());
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size()) {
      const int hi = detail::uri_hex_value(uri[i + 1]), lo = detail::uri_hex_value(uri[i + 2]);
      if (hi >= 0 && lo >= 0) {
        out += static_cast<char>(hi * 16 + lo);
        i += 2;
        continue;
      }
    }
    out += uri[i];
  }
  return out;
}

bool is_data_uri(const std::string& uri) {
  if (uri.size() < 5) return false;
  for (int i = 0; i < 4; ++i)
    if (std::tolower(static_cast<unsigned char>(uri[i])) != "data"[i]) return false;
  return uri[4] == ':';
}

Status check_relative_uri(const std::string& uri, const std::string& what) {
  auto refuse = [&](const std::string& why) {
    return Status::error(StatusCode::IoError, what + " refers to '" + quote_input(uri) + "': " + why +
                                                  "; only files inside the glTF file's own folder can be used");
  };
  if (uri.empty()) return refuse("empty URI");
  if (uri.find('\0') != std::string::npos) return refuse("NUL byte in the URI");
  if (uri[0] == '/' || uri[0] == '\\') return refuse("absolute paths are refused");
  // A scheme is letters/digits/+/-/. before the first ':' (RFC 3986); a Windows drive letter
  // ("C:") looks the same and is refused for the same reason.
  const size_t colon = uri.find(':');
  if (colon != std::string::npos) {
    bool scheme = colon > 0;
    for (size_t i = 0; i < colon && scheme; ++i) {
      const unsigned char c = static_cast<unsigned char>(uri[i]);
      scheme = std::isalnum(c) || c == '+' || c == '-' || c == '.';
    }
    if (scheme) return refuse("URI schemes other than data: are refused");
  }
  size_t begin = 0;
  while (begin <= uri.size()) {
    size_t end = uri.find_first_of("/\\", begin);
    if (end == std::string::npos) end = uri.size();
    if (uri.compare(begin, end - begin, "..") == 0) return refuse("'..' path segments are refused");
    begin = end + 1;
  }
  return Status::success();
}

bool decode_data_uri(const std::string& uri, std::string* mime, std::vector<uint8_t>* bytes) {
  if (!is_data_uri(uri)) return false;
  const size_t comma = uri.find(',');
  if (comma == std::string::npos) return false;
  const std::string meta = uri.substr(5, comma - 5);
  const size_t b64 = meta.rfind(";base64");
  if (b64 == std::string::npos || b64 + 7 != meta.size()) return false;
  *mime = meta.substr(0, b64);
  bytes->clear();
  bytes->reserve((uri.size() - comma) * 3 / 4);
  unsigned buffer = 0;
  int bits = 0;
  for (size_t i = comma + 1; i < uri.size(); ++i) {
    const char c = uri[i];
    if (c == '=') break;
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    const int v = detail::uri_base64_value(c);
    if (v < 0) return false;
    buffer = (buffer << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes->push_back(static_cast<uint8_t>((buffer >> bits) & 0xFF));
    }
  }
  return true;
}

std::string encode_data_uri(const std::string& mime, const uint8_t* data, size_t size) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out = "data:" + mime + ";base64,";
  out.reserve(out.size() + (size + 2) / 3 * 4);
  for (size_t i = 0; i < size; i += 3) {
    const unsigned a = data[i], b = i + 1 < size ? data[i + 1] : 0, c = i + 2 < size ? data[i + 2] : 0;
    const unsigned triple = (a << 16) | (b << 8) | c;
    out += alphabet[(triple >> 18) & 63];
    out += alphabet[(triple >> 12) & 63];
    out += i + 1 < size ? alphabet[(triple >> 6) & 63] : '=';
    out += i + 2 < size ? alphabet[triple & 63] : '=';
  }
  return out;
}

}  // namespace mm::io

namespace mm::io {
std::string image_mime_from_uri(const std::string& uri) {
  const size_t dot = uri.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string ext = uri.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == "png") return "image/png";
  if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
  if (ext == "webp") return "image/webp";
  if (ext == "ktx2") return "image/ktx2";
  return "";
}
}  // namespace mm::io
