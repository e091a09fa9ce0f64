// Small CLI toolkit shared by the subcommands: argument parsing, the stderr progress bar,
// status → exit code. No geometry here (that lives in core/).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "app/option_schema.h"
#include "common/progress.h"
#include "common/status.h"

namespace mm::cli {

// Parsed command line of one subcommand: positional arguments and --flags.
// "--name value" and "--name=value" are both accepted; a flag listed in `switches`
// takes no value.
class Args {
 public:
  Status parse(const std::vector<std::string>& argv, const std::vector<std::string>& switches = {});
  const std::vector<std::string>& positional() const { return positional_; }
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string get(const std::string& name, const std::string& fallback = "") const;
  // Parses a number; `*error` is set when the value is present but not a number.
  double get_double(const std::string& name, double fallback, Status* error) const;
  int get_int(const std::string& name, int fallback, Status* error) const;
  // Flags given but never read (typos); call after reading everything.
  std::vector<std::string> unused() const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;
  mutable std::map<std::string, bool> read_;
};

// Reads every option of `schema` given on the command line (--name-with-dashes VALUE) into *o.
template <class O>
Status read_options(const Args& args, const app::OptionSchema<O>& schema, O* o) {
  for (const auto& e : schema.entries()) {
    const std::string flag = e.info.cli_flag().substr(2);
    if (!args.has(flag)) continue;
    if (Status s = e.set(*o, app::OptionValue::of_text(args.get(flag))); !s.ok())
      return Status::error(s.code, "--" + flag + ": " + s.message);
  }
  return Status::success();
}

// The "unknown option --x" error for flags nobody read (typos), or success.
Status check_unused(const Args& args);

// A progress sink drawing a bar on stderr — only when stderr is a terminal.
Progress terminal_progress();

// Prints "meshmorph <command>: error: <message> [<code>]" to stderr and returns the exit code
// for `s` (0 for ok, 2 for bad arguments, 3 for bad input data, 4 for I/O, 5 for numerical
// failures, 130 for cancel).
int report(const std::string& command, const Status& s);

using CommandFn = std::function<int(const std::vector<std::string>& args)>;
struct Command {
  std::string name;
  std::string summary;  // one line for `meshmorph --help`
  CommandFn run;
};

// Called from static registrars in native/commands/*.cpp.
bool register_command(Command c);
const std::map<std::string, Command>& commands();

}  // namespace mm::cli

// Registers a subcommand at static-initialisation time: MM_COMMAND(info, "summary", fn).
#define MM_COMMAND(name, summary, fn) \
  static const bool mm_registered_##name = ::mm::cli::register_command({#name, summary, fn})
