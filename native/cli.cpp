#include "cli.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

namespace mm::cli {

Status Args::parse(const std::vector<std::string>& argv, const std::vector<std::string>& switches) {
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.size() > 2 && a.rfind("--", 0) == 0) {
      std::string name = a.substr(2), value;
      const auto eq = name.find('=');
      bool is_switch = false;
      for (const auto& s : switches) is_switch |= (s == name);
      if (eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
      } else if (!is_switch) {
        if (i + 1 >= argv.size())
          return Status::error(StatusCode::InvalidArgument, "option --" + name + " needs a value");
        value = argv[++i];
      }
      values_[name] = value;
    } else if (a.size() == 2 && a[0] == '-' && a[1] != '-' && !std::isdigit(static_cast<unsigned char>(a[1]))) {
      // Short option with a value: -k 20
      if (i + 1 >= argv.size())
        return Status::error(StatusCode::InvalidArgument, "option " + a + " needs a value");
      values_[a.substr(1)] = argv[++i];
    } else {
      positional_.push_back(a);
    }
  }
  return Status::success();
}

Status check_unused(const Args& args) {
  for (const auto& u : args.unused()) {
    const std::string shown = u.size() > 60 ? u.substr(0, 60) + "..." : u;
    return Status::error(StatusCode::InvalidArgument, "unknown option --" + shown);
  }
  return Status::success();
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  read_[name] = true;
  return it->second;
}

double Args::get_double(const std::string& name, double fallback, Status* error) const {
  if (!has(name)) return fallback;
  const std::string v = get(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !std::isfinite(d)) {
    if (error && error->ok())
      *error = Status::error(StatusCode::InvalidArgument, "--" + name + " expects a number, got '" + v + "'");
    return fallback;
  }
  return d;
}

int Args::get_int(const std::string& name, int fallback, Status* error) const {
  if (!has(name)) return fallback;
  const std::string v = get(name);
  char* end = nullptr;
  const long d = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0') {
    if (error && error->ok())
      *error = Status::error(StatusCode::InvalidArgument, "--" + name + " expects an integer, got '" + v + "'");
    return fallback;
  }
  return static_cast<int>(d);
}

std::vector<std::string> Args::unused() const {
  std::vector<std::string> out;
  for (const auto& [k, v] : values_)
    if (!read_.count(k)) out.push_back(k);
  return out;
}

Progress terminal_progress() {
  if (!isatty(STDERR_FILENO)) return Progress();
  struct Bar {
    std::string stage;
    int last_percent = -1;
    std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();
  };
  auto bar = std::make_shared<Bar>();
  return Progress([bar](const std::string& stage, double f) {
    const int percent = static_cast<int>(f * 100.0 + 0.5);
    const auto now = std::chrono::steady_clock::now();
    if (percent == bar->last_percent && stage == bar->stage) return true;
    if (percent < 100 && stage == bar->stage &&
        now - bar->last < std::chrono::milliseconds(50))
      return true;
    bar->stage = stage;
    bar->last_percent = percent;
    bar->last = now;
    const int width = 30, filled = percent * width / 100;
    std::fprintf(stderr, "\r\033[K[%s%s] %3d%% %s", std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), percent, stage.c_str());
    if (percent >= 100) std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    return true;
  });
}

int report(const std::string& command, const Status& s) {
  if (s.ok()) return 0;
  if (isatty(STDERR_FILENO)) std::fprintf(stderr, "\r\033[K");
  std::cerr << "meshmorph " << command << ": error: " << s.message << " [" << status_code_name(s.code) << "]\n";
  switch (s.code) {
    case StatusCode::Ok: return 0;
    case StatusCode::InvalidArgument: return 2;
    case StatusCode::InvalidMesh:
    case StatusCode::ParseError:
    case StatusCode::Unsupported: return 3;
    case StatusCode::IoError: return 4;
    case StatusCode::Cancelled: return 130;
    default: return 5;
  }
}

namespace {
std::map<std::string, Command>& registry() {
  static std::map<std::string, Command> r;
  return r;
}
}  // namespace

bool register_command(Command c) {
  registry()[c.name] = std::move(c);
  return true;
}

const std::map<std::string, Command>& commands() { return registry(); }

}  // namespace mm::cli
