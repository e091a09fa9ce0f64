#include "io/json_text.h"

namespace mm::io {

Status check_json_depth(std::string_view text, const std::string& what, int max_depth) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;  // skip the escaped character (\" does not end the string)
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '[' || c == '{') {
      if (++depth > max_depth)
        return Status::error(StatusCode::ParseError, what + ": JSON nested deeper than " + std::to_string(max_depth) +
                                                         " levels (at byte " + std::to_string(i) + ")");
    } else if (c == ']' || c == '}') {
      if (depth > 0) --depth;
    }
  }
  return Status::success();
}

std::string quote_input(std::string_view text, size_t max) {
  std::string out;
  size_t n = text.size() <= max ? text.size() : max;
  // Do not cut inside a UTF-8 sequence (the page shows the message; a torn sequence shows as junk).
  if (n < text.size())
    while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;
  out.reserve(n + 24);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    out += (c < 0x20 || c == 0x7f) ? '?' : static_cast<char>(c);
  }
  if (text.size() > max) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

std::string cap_message(std::string message, size_t max) {
  if (message.size() <= max) return message;
  // Do not cut inside a UTF-8 sequence.
  size_t cut = max;
  while (cut > 0 && (static_cast<unsigned char>(message[cut]) & 0xC0) == 0x80) --cut;
  message.resize(cut);
  return message + "... (cut)";
}

}  // namespace mm::io
