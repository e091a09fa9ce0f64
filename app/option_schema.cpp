#include "app/option_schema.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mm::app {

const char* option_kind_name(OptionKind k) {
  switch (k) {
    case OptionKind::Integer: return "integer";
    case OptionKind::Number: return "number";
    case OptionKind::Boolean: return "boolean";
    case OptionKind::Choice: return "choice";
    case OptionKind::Text: return "text";
  }
  return "?";
}

std::string format_number(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[40];
  if (x == std::floor(x) && std::fabs(x) < 1e15) {  // whole numbers as integers ("200000", not "2e+05")
    std::snprintf(buf, sizeof buf, "%.0f", x);
    return buf;
  }
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

std::string OptionInfo::cli_flag() const {
  std::string f = "--" + name;
  for (char& c : f)
    if (c == '_') c = '-';
  return f;
}

std::string OptionInfo::placeholder() const {
  switch (kind) {
    case OptionKind::Integer: return "N";
    case OptionKind::Number: return "X";
    case OptionKind::Boolean: return "true|false";
    case OptionKind::Text: return "TEXT";
    case OptionKind::Choice: {
      std::string s;
      for (const std::string& c : choices) s += (s.empty() ? "" : "|") + c;
      return s;
    }
  }
  return "";
}

std::string OptionInfo::range_text() const {
  if (kind != OptionKind::Integer && kind != OptionKind::Number) return "";
  const bool lo = std::isfinite(min), hi = std::isfinite(max);
  if (lo && hi) return format_number(min) + ".." + format_number(max);
  if (lo) return (min == 0 && kind == OptionKind::Number ? "≥ 0" : "≥ " + format_number(min));
  if (hi) return "≤ " + format_number(max);
  return "";
}

namespace option_detail {
namespace {

// The value as the user gave it, shortened (an error never echoes a megabyte of input).
std::string shown(const OptionValue& v) {
  switch (v.type) {
    case OptionValue::Type::Number: return format_number(v.number);
    case OptionValue::Type::Boolean: return v.boolean ? "true" : "false";
    case OptionValue::Type::Text: return "'" + (v.text.size() > 40 ? v.text.substr(0, 40) + "..." : v.text) + "'";
  }
  return "";
}

Status bad(const OptionInfo& info, const OptionValue& v, const std::string& expected) {
  return Status::error(StatusCode::InvalidArgument, "option " + info.name + " must be " + expected + ", got " + shown(v));
}

std::string range_phrase(const OptionInfo& info) {
  const std::string r = info.range_text();
  if (r.empty()) return "";
  if (r.find("..") != std::string::npos) return " in " + r;
  return " " + r;
}

// Strict parse of a whole string as a double (no trailing text, finite).
bool parse_double(const std::string& s, double* out) {
  if (s.empty() || s.size() > 64) return false;
  errno = 0;
  char* end = nullptr;
  const double x = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(x)) return false;
  *out = x;
  return true;
}

bool numeric_value(const OptionValue& v, double* x) {
  if (v.type == OptionValue::Type::Number) {
    *x = v.number;
    return std::isfinite(v.number);
  }
  if (v.type == OptionValue::Type::Text) return parse_double(v.text, x);
  return false;
}

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          o += buf;
        } else {
          o += c;
        }
    }
  }
  return o + "\"";
}

std::string json_default(const OptionInfo& info) {
  switch (info.kind) {
    case OptionKind::Integer:
    case OptionKind::Number: return info.default_text;
    case OptionKind::Boolean: return info.default_text;
    default: return json_string(info.default_text);
  }
}

}  // namespace

Status to_integer(const OptionInfo& info, const OptionValue& v, int* out) {
  double x = 0;
  const std::string expected = "an integer" + range_phrase(info);
  if (!numeric_value(v, &x) || x != std::floor(x) || std::fabs(x) > 2e9) return bad(info, v, expected);
  if (x < info.min || x > info.max) return bad(info, v, expected);
  *out = static_cast<int>(x);
  return Status::success();
}

Status to_number(const OptionInfo& info, const OptionValue& v, double* out) {
  double x = 0;
  const std::string expected = "a number" + range_phrase(info);
  if (!numeric_value(v, &x) || x < info.min || x > info.max) return bad(info, v, expected);
  *out = x;
  return Status::success();
}

Status to_boolean(const OptionInfo& info, const OptionValue& v, bool* out) {
  if (v.type == OptionValue::Type::Boolean) {
    *out = v.boolean;
    return Status::success();
  }
  if (v.type == OptionValue::Type::Text && (v.text == "true" || v.text == "1" || v.text.empty())) {
    *out = true;  // empty: a bare CLI switch
    return Status::success();
  }
  if (v.type == OptionValue::Type::Text && (v.text == "false" || v.text == "0")) {
    *out = false;
    return Status::success();
  }
  return bad(info, v, "true or false");
}

Status to_choice(const OptionInfo& info, const OptionValue& v, int* index) {
  if (v.type == OptionValue::Type::Text)
    for (size_t k = 0; k < info.choices.size(); ++k)
      if (info.choices[k] == v.text) {
        *index = static_cast<int>(k);
        return Status::success();
      }
  std::string list;
  for (size_t k = 0; k < info.choices.size(); ++k)
    list += (k ? (k + 1 == info.choices.size() ? " or " : ", ") : "") + info.choices[k];
  return bad(info, v, list);
}

Status to_text(const OptionInfo& info, const OptionValue& v, std::string* out) {
  if (v.type != OptionValue::Type::Text || v.text.size() > 1000) return bad(info, v, "a text of at most 1000 characters");
  *out = v.text;
  return Status::success();
}

std::string schema_json(const std::string& job, const std::string& summary, const std::vector<OptionInfo>& options) {
  std::string o = "{\"job\": " + json_string(job) + ", \"summary\": " + json_string(summary) + ", \"options\": [";
  for (size_t i = 0; i < options.size(); ++i) {
    const OptionInfo& info = options[i];
    o += i ? ",\n  " : "\n  ";
    o += "{\"name\": " + json_string(info.name) + ", \"kind\": \"" + option_kind_name(info.kind) + "\"";
    o += ", \"default\": " + json_default(info);
    if (std::isfinite(info.min)) o += ", \"min\": " + format_number(info.min);
    if (std::isfinite(info.max)) o += ", \"max\": " + format_number(info.max);
    if (!info.choices.empty()) {
      o += ", \"choices\": [";
      for (size_t k = 0; k < info.choices.size(); ++k) o += (k ? ", " : "") + json_string(info.choices[k]);
      o += "]";
    }
    o += ", \"flag\": " + json_string(info.cli_flag()) + ", \"help\": " + json_string(info.help) + "}";
  }
  return o + "\n]}";
}

std::string help_text(const std::vector<OptionInfo>& options) {
  std::string o;
  for (const OptionInfo& info : options) {
    std::string head = "  " + info.cli_flag() + " " + info.placeholder();
    if (head.size() < 34) head.resize(34, ' ');
    else head += "\n" + std::string(34, ' ');
    std::string tail = "(default " + (info.default_text.empty() ? std::string("none") : info.default_text);
    const std::string range = info.range_text();
    if (!range.empty()) tail += "; " + range;
    o += head + info.help + " " + tail + ")\n";
  }
  return o;
}

}  // namespace option_detail
}  // namespace mm::app
