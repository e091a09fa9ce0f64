// Small text helpers shared by the OBJ, OFF and PLY readers and writers (io-internal).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace mm::io::detail {

// Splits bytes into lines; accepts \n, \r\n and lone \r endings. Lines exclude the ending.
class TextLines {
 public:
  TextLines(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  // Next line into *line; false at the end of the data.
  bool next(std::string_view* line);
  int line_number() const { return line_number_; }  // 1-based number of the last line read
  size_t offset() const { return pos_; }            // byte offset after the last line read
  bool saw_crlf() const { return saw_crlf_; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  int line_number_ = 0;
  bool saw_crlf_ = false;
};

// Whitespace-separated tokens of a line.
std::vector<std::string_view> split_tokens(std::string_view line);
// The same into *out (cleared first), reusing its storage: the readers call it once a line.
void split_tokens(std::string_view line, std::vector<std::string_view>* out);
// The line without a trailing comment starting at `comment` and without surrounding blanks.
std::string_view strip_comment(std::string_view line, char comment);

// Strict number parsing of a whole token (C locale). False on garbage or overflow.
bool parse_double_token(std::string_view token, double* value);
bool parse_int_token(std::string_view token, long long* value);

// Shortest decimal text that reads back as exactly `value` (%.15g, else %.17g); NaN/Inf as
// "nan"/"inf". Deterministic across platforms.
std::string format_double(double value);

// Appends text to a byte vector.
void append_text(std::vector<uint8_t>* out, std::string_view text);

}  // namespace mm::io::detail
