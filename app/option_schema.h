// One options schema per job: every option of a workflow named once, with its default (read from
// the algorithm's Options struct, whose defaults are the papers' values), its range and a
// one-line help. The CLI flags and `--help` text (native/), the wasm option parsing (wasm/) and
// the page's options panel (through `optionSchema(job)` → JSON) are all generated from it, so a
// default changed in an Options struct changes everywhere, and a name cannot drift between doors.
//
// Naming: `name` is snake_case; it is the key in JS option objects and in JSON specs, and the CLI
// flag is `--` + name with '_' → '-' (num_low_frequencies ↔ --num-low-frequencies).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"

namespace mm::app {

// Upper bound of an option without one.
constexpr double kUnbounded = std::numeric_limits<double>::infinity();

enum class OptionKind { Integer, Number, Boolean, Choice, Text };

const char* option_kind_name(OptionKind k);  // "integer", "number", "boolean", "choice", "text"

// A value as a door received it: a JSON/JS number or boolean, or text (CLI arguments, JSON strings).
struct OptionValue {
  enum class Type { Number, Boolean, Text } type = Type::Text;
  double number = 0;
  bool boolean = false;
  std::string text;
  static OptionValue of_number(double x) { return {Type::Number, x, false, {}}; }
  static OptionValue of_boolean(bool b) { return {Type::Boolean, 0, b, {}}; }
  static OptionValue of_text(std::string s) { return {Type::Text, 0, false, std::move(s)}; }
};

// What every door sees of one option.
struct OptionInfo {
  std::string name;
  OptionKind kind = OptionKind::Number;
  double min = -std::numeric_limits<double>::infinity();  // Integer, Number: inclusive range
  double max = std::numeric_limits<double>::infinity();
  std::vector<std::string> choices;                        // Choice
  std::string help;                                        // one line
  std::string default_text;                                // the default as text ("0.05", "yin", "true")
  std::string cli_flag() const;                            // "--" + name with '_' → '-'
  std::string placeholder() const;                         // "N", "X", "yin|kovnatsky|levy", "true|false", "TEXT"
  std::string range_text() const;                          // "≥ 0", "1..3", "" (unbounded)
};

// Shortest decimal text that reads back as the same double ("0.05", "200000", "1e-06").
std::string format_number(double x);

namespace option_detail {
// Checks `v` against `info` and converts it; the error names the option and the expected kind.
Status to_integer(const OptionInfo& info, const OptionValue& v, int* out);
Status to_number(const OptionInfo& info, const OptionValue& v, double* out);
Status to_boolean(const OptionInfo& info, const OptionValue& v, bool* out);
Status to_choice(const OptionInfo& info, const OptionValue& v, int* index);
Status to_text(const OptionInfo& info, const OptionValue& v, std::string* out);
std::string schema_json(const std::string& job, const std::string& summary, const std::vector<OptionInfo>& options);
std::string help_text(const std::vector<OptionInfo>& options);
}  // namespace option_detail

// The schema of one job's options struct O (default-constructible; its defaults are the schema's).
template <class O>
class OptionSchema {
 public:
  struct Entry {
    OptionInfo info;
    std::function<Status(O&, const OptionValue&)> set;
  };

  OptionSchema(std::string job, std::string summary) : job_(std::move(job)), summary_(std::move(summary)) {}

  OptionSchema& integer(const std::string& name, std::function<int&(O&)> field, double min, double max,
                        const std::string& help) {
    OptionInfo info = make(name, OptionKind::Integer, help);
    info.min = min;
    info.max = max;
    O d;
    info.default_text = std::to_string(field(d));
    entries_.push_back({info, [info, field](O& o, const OptionValue& v) { return option_detail::to_integer(info, v, &field(o)); }});
    return *this;
  }
  OptionSchema& number(const std::string& name, std::function<double&(O&)> field, double min, double max,
                       const std::string& help) {
    OptionInfo info = make(name, OptionKind::Number, help);
    info.min = min;
    info.max = max;
    O d;
    info.default_text = format_number(field(d));
    entries_.push_back({info, [info, field](O& o, const OptionValue& v) { return option_detail::to_number(info, v, &field(o)); }});
    return *this;
  }
  OptionSchema& boolean(const std::string& name, std::function<bool&(O&)> field, const std::string& help) {
    OptionInfo info = make(name, OptionKind::Boolean, help);
    O d;
    info.default_text = field(d) ? "true" : "false";
    entries_.push_back({info, [info, field](O& o, const OptionValue& v) { return option_detail::to_boolean(info, v, &field(o)); }});
    return *this;
  }
  OptionSchema& text(const std::string& name, std::function<std::string&(O&)> field, const std::string& help) {
    OptionInfo info = make(name, OptionKind::Text, help);
    O d;
    info.default_text = field(d);
    entries_.push_back({info, [info, field](O& o, const OptionValue& v) { return option_detail::to_text(info, v, &field(o)); }});
    return *this;
  }
  // An enum field: `values` pairs each accepted word with its enumerator.
  template <class E>
  OptionSchema& choice(const std::string& name, std::function<E&(O&)> field, std::vector<std::pair<std::string, E>> values,
                       const std::string& help) {
    OptionInfo info = make(name, OptionKind::Choice, help);
    O d;
    for (const auto& [word, e] : values) {
      info.choices.push_back(word);
      if (e == field(d)) info.default_text = word;
    }
    entries_.push_back({info, [info, field, values](O& o, const OptionValue& v) {
                          int k = -1;
                          Status s = option_detail::to_choice(info, v, &k);
                          if (s.ok()) field(o) = values[static_cast<size_t>(k)].second;
                          return s;
                        }});
    return *this;
  }

  const std::string& job() const { return job_; }
  const std::string& summary() const { return summary_; }
  const std::vector<Entry>& entries() const { return entries_; }
  std::vector<OptionInfo> infos() const {
    std::vector<OptionInfo> out;
    for (const Entry& e : entries_) out.push_back(e.info);
    return out;
  }
  const Entry* find(const std::string& name) const {
    for (const Entry& e : entries_)
      if (e.info.name == name) return &e;
    return nullptr;
  }
  // Sets option `name` of `o`. Unknown names and bad values: InvalidArgument naming the option.
  Status set(O& o, const std::string& name, const OptionValue& v) const {
    const Entry* e = find(name);
    if (!e) return Status::error(StatusCode::InvalidArgument, unknown_message(name));
    return e->set(o, v);
  }
  std::string unknown_message(const std::string& name) const {
    std::string known;
    for (const Entry& e : entries_) known += (known.empty() ? "" : ", ") + e.info.name;
    const std::string shown = name.size() > 60 ? name.substr(0, 60) + "..." : name;
    return "unknown " + job_ + " option '" + shown + "' (options: " + known + ")";
  }
  // {"job": ..., "summary": ..., "options": [{"name", "kind", "default", "min", "max", "choices", "help", "flag"}]}
  std::string json() const { return option_detail::schema_json(job_, summary_, infos()); }
  // One line per option: "  --flag X   help (default D; range)".
  std::string help() const { return option_detail::help_text(infos()); }

 private:
  static OptionInfo make(const std::string& name, OptionKind kind, const std::string& help) {
    OptionInfo info;
    info.name = name;
    info.kind = kind;
    info.help = help;
    return info;
  }
  std::string job_, summary_;
  std::vector<Entry> entries_;
};

}  // namespace mm::app
