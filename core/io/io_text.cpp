#include "io/io_text.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdint>
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

void split_tokens(std::string_view line, std::vector<std::string_view>* out) {
  out->clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && io_text_is_blank(line[i])) ++i;
    const size_t b = i;
    while (i < line.size() && !io_text_is_blank(line[i])) ++i;
    if (i > b) out->push_back(line.substr(b, i - b));
  }
}

std::vector<std::string_view> split_tokens(std::string_view line) {
  std::vector<std::string_view> out;
  split_tokens(line, &out);
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

// Clinger's fast path: a decimal [sign] digits [. digits] [e [sign] digits] whose significand
// m fits in 53 bits and whose power of ten 10^k has |k| <= 22 is m * 10^k or m / 10^-k, both
// exact operands, so one IEEE operation gives the correctly rounded double — the value strtod
// returns. Mesh files are almost all such tokens ("0.512263", "-1.25e-3"). Emscripten's strtod
// (musl's) took ~3 µs a token: michael3.off (52k vertices) loaded in 628 ms in wasm against 83 ms
// natively. Anything else (more digits, inf/nan, hex, malformed) returns false for strtod to decide.
static bool io_text_fast_double(std::string_view t, double* value) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                      1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  size_t i = 0;
  const size_t n = t.size();
  const bool negative = i < n && t[i] == '-';
  if (i < n && (t[i] == '-' || t[i] == '+')) ++i;
  uint64_t m = 0;
  int digits = 0, frac = 0;  // significant digits kept in m, digits after the point
  bool any = false;
  for (; i < n && t[i] >= '0' && t[i] <= '9'; ++i) {
    any = true;
    if (m == 0 && t[i] == '0') continue;  // leading zeros
    if (++digits > 18) return false;
    m = 10 * m + static_cast<uint64_t>(t[i] - '0');
  }
  if (i < n && t[i] == '.') {
    for (++i; i < n && t[i] >= '0' && t[i] <= '9'; ++i) {
      any = true;
      ++frac;
      if (m == 0 && t[i] == '0') continue;
      if (++digits > 18) return false;
      m = 10 * m + static_cast<uint64_t>(t[i] - '0');
    }
  }
  if (!any) return false;
  int e = 0;
  if (i < n && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    const bool eneg = i < n && t[i] == '-';
    if (i < n && (t[i] == '-' || t[i] == '+')) ++i;
    if (i == n) return false;
    for (; i < n && t[i] >= '0' && t[i] <= '9'; ++i) {
      if (e > 1000) return false;
      e = 10 * e + (t[i] - '0');
    }
    if (eneg) e = -e;
  }
  if (i != n || m > (uint64_t(1) << 53)) return false;
  const int k = e - frac;
  double v = static_cast<double>(m);
  if (m == 0) v = 0.0;
  else if (k >= 0 && k <= 22) v *= kPow10[k];
  else if (k < 0 && k >= -22) v /= kPow10[-k];
  else return false;
  *value = negative ? -v : v;
  return true;
}

bool parse_double_token(std::string_view token, double* value) {
  if (io_text_fast_double(token, value)) return true;
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
  // Fast path: [sign] up to 18 digits (no overflow possible); strtoll decides anything else.
  {
    size_t i = 0;
    const bool negative = !token.empty() && token[0] == '-';
    if (!token.empty() && (token[0] == '-' || token[0] == '+')) ++i;
    const size_t digits = token.size() - i;
    if (digits > 0 && digits <= 18) {
      long long v = 0;
      for (; i < token.size() && token[i] >= '0' && token[i] <= '9'; ++i) v = 10 * v + (token[i] - '0');
      if (i == token.size()) {
        *value = negative ? -v : v;
        return true;
      }
    }
  }
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
