#include "io/io_text.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mm::io::detail {

bool TextLines::next(std::string_view* line) {
  if (pos_ >= size_) return false;
  const size_t begin = pos_;
  size_t end = begin;
  while (end < size_ && data_[end] != '\n' && data_[end] != '\r') ++end;
  *line = std::string_view(reinterpret_cast<const char*>(data_) + begin, end - begin);
  pos_ = end;
  if (pos_ < size_ && data_[pos_] == '\r') {
    ++pos_;
    if (pos_ < size_ && data_[pos_] == '\n') {
      ++pos_;
      saw_crlf_ = true;
    }
  } else if (pos_ < size_) {
    ++pos_;
  }
  ++line_number_;
  return true;
}

static bool io_text_is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

std::vector<std::string_view> split_tokens(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && io_text_is_blank(line[i])) ++i;
    const size_t b = i;
    while (i < line.size() && !io_text_is_blank(line[i])) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

std::string_view strip_comment(std::string_view line, char comment) {
  const size_t c = line.find(comment);
  if (c != std::string_view::npos) line = line.substr(0, c);
  size_t b = 0, e = line.size();
  while (b < e && io_text_is_blank(line[b])) ++b;
  while (e > b && io_text_is_blank(line[e - 1])) --e;
  return line.substr(b, e - b);
}

bool parse_double_token(std::string_view token, double* value) {
  // strtod needs a terminated string; tokens are short, so a stack copy suffices.
  char buf[64];
  if (token.empty() || token.size() >= sizeof(buf)) return false;
  token.copy(buf, token.size());
  buf[token.size()] = '\0';
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(buf, &end);
  if (end != buf + token.size()) return false;
  // Underflow to 0 / denormals is harmless for coordinates; overflow is not.
  if (errno == ERANGE && std::isinf(v)) return false;
  *value = v;
  return true;
}

bool parse_int_token(std::string_view token, long long* value) {
  char buf[32];
  if (token.empty() || token.size() >= sizeof(buf)) return false;
  token.copy(buf, token.size());
  buf[token.size()] = '\0';
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(buf, &end, 10);
  if (end != buf + token.size() || errno == ERANGE) return false;
  *value = v;
  return true;
}

std::string format_double(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (value == 0) return "0";  // also folds -0, which some readers reject
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.15g", value);
  if (std::strtod(buf, nullptr) != value) std::snprintf(buf, sizeof(buf), "%.17g", value);
  return buf;
}

void append_text(std::vector<uint8_t>* out, std::string_view text) {
  out->insert(out->end(), text.begin(), text.end());
}

}  // namespace mm::io::detail
