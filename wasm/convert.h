// Converters between JS values and core types for the embind bindings (wasm/bind_*.cpp).
// No geometry here. Outputs are copied into JS-owned typed arrays (never views into the wasm
// heap, which moves when memory grows).
#pragma once

#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include <emscripten/val.h>
#include <Eigen/Core>

#include "app/option_schema.h"
#include "common/progress.h"
#include "common/status.h"

namespace mm::wasm {

// Float32Array/Float64Array/Array of length 3n → n by 3 (cols) matrix.
Eigen::MatrixXd to_matrix(const emscripten::val& array, int cols = 3);
// Uint32Array/Int32Array/Array of length 3m → m by 3 int matrix.
Eigen::MatrixXi to_index_matrix(const emscripten::val& array, int cols = 3);
// Uint8Array → bytes.
std::vector<uint8_t> to_bytes(const emscripten::val& array);
std::vector<int> to_int_vector(const emscripten::val& array);

// Row-major copies into new typed arrays.
emscripten::val to_float32_array(const Eigen::MatrixXd& M);
emscripten::val to_float64_array(const Eigen::MatrixXd& M);
emscripten::val to_uint32_array(const Eigen::MatrixXi& M);
emscripten::val to_uint8_array(const std::vector<uint8_t>& bytes);

// Options object helpers: a missing or undefined field returns the default.
double get_number(const emscripten::val& obj, const char* name, double fallback);
int get_int(const emscripten::val& obj, const char* name, int fallback);
bool get_bool(const emscripten::val& obj, const char* name, bool fallback);
std::string get_string(const emscripten::val& obj, const char* name, const std::string& fallback);

// { ok: true } or { ok: false, code: "InvalidMesh", message: "..." }. Bindings return an object
// built on top of this (set more fields on it when ok).
emscripten::val status_object(const Status& s);

// {ok:false, code, message} for an exception that escaped a binding (guard.h).
emscripten::val exception_object(const std::string& what, const std::exception* e, bool out_of_memory);

// Options object → a job's options through its schema (app/*_job.h): every key must be an option
// of the schema; undefined/null values keep the default. Errors name the option.
Status read_js_option_value(const emscripten::val& v, const std::string& key, app::OptionValue* out);
std::vector<std::string> js_object_keys(const emscripten::val& obj);
template <class O>
Status read_options(const emscripten::val& obj, const app::OptionSchema<O>& schema, O* o) {
  for (const std::string& key : js_object_keys(obj)) {
    const emscripten::val v = obj[key];
    if (v.isUndefined() || v.isNull()) continue;
    app::OptionValue value;
    Status s = read_js_option_value(v, key, &value);
    if (s.ok()) s = schema.set(*o, key, value);
    if (!s.ok()) return s;
  }
  return Status::success();
}

// A Progress that calls `callback(stage, fraction)` (a JS function) and cancels when it returns
// false. An undefined callback gives a no-op Progress.
Progress js_progress(const emscripten::val& callback);

}  // namespace mm::wasm
