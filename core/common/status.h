// Status: how the core reports failures caused by the data (never by exceptions).
//
// Every core entry point that can fail on user input returns a result struct with a
// `Status status` member; callers check `status.ok()` before reading the rest.
// Programmer mistakes (wrong shapes passed between our own functions) are asserts.
#pragma once

#include <string>

namespace mm {

enum class StatusCode {
  Ok = 0,
  InvalidArgument,      // options or parameters out of range (k too large, empty selection, ...)
  InvalidMesh,          // geometry/topology unusable for the requested method
  IoError,              // file missing, unreadable, unwritable, or a refused path
  ParseError,           // malformed file contents
  Unsupported,          // valid input that we do not handle (e.g. glTF line primitives)
  FactorizationFailed,  // sparse factorization reported failure (not SPD, singular)
  NotConverged,         // iterative solver hit its iteration limit
  NumericalError,       // a computed output was NaN/Inf
  Cancelled,            // the progress sink asked to stop
};

// Stable machine-readable name ("InvalidMesh") used by the CLI (--json) and the wasm binding.
const char* status_code_name(StatusCode code);

struct Status {
  StatusCode code = StatusCode::Ok;
  std::string message;  // a sentence a user can act on; empty when ok

  bool ok() const { return code == StatusCode::Ok; }
  static Status success() { return {}; }
  static Status error(StatusCode c, std::string msg) { return {c, std::move(msg)}; }
};

}  // namespace mm
