#include "convert.h"

#include <emscripten/bind.h>

namespace mm::wasm {

using emscripten::val;

namespace {
std::vector<double> to_doubles(const val& array) {
  if (array.isUndefined() || array.isNull()) return {};
  return emscripten::convertJSArrayToNumberVector<double>(array);
}
}  // namespace

Eigen::MatrixXd to_matrix(const val& array, int cols) {
  const std::vector<double> d = to_doubles(array);
  const int rows = static_cast<int>(d.size()) / cols;
  Eigen::MatrixXd M(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) M(r, c) = d[r * cols + c];
  return M;
}

Eigen::MatrixXi to_index_matrix(const val& array, int cols) {
  const std::vector<double> d = to_doubles(array);
  const int rows = static_cast<int>(d.size()) / cols;
  Eigen::MatrixXi M(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) M(r, c) = static_cast<int>(d[r * cols + c]);
  return M;
}

std::vector<uint8_t> to_bytes(const val& array) {
  if (array.isUndefined() || array.isNull()) return {};
  return emscripten::convertJSArrayToNumberVector<uint8_t>(array);
}

std::vector<int> to_int_vector(const val& array) {
  if (array.isUndefined() || array.isNull()) return {};
  return emscripten::convertJSArrayToNumberVector<int>(array);
}

val to_float32_array(const Eigen::MatrixXd& M) {
  std::vector<float> buf(M.size());
  for (int r = 0; r < M.rows(); ++r)
    for (int c = 0; c < M.cols(); ++c) buf[r * M.cols() + c] = static_cast<float>(M(r, c));
  val out = val::global("Float32Array").new_(buf.size());
  out.call<void>("set", val(emscripten::typed_memory_view(buf.size(), buf.data())));
  return out;
}

val to_float64_array(const Eigen::MatrixXd& M) {
  std::vector<double> buf(M.size());
  for (int r = 0; r < M.rows(); ++r)
    for (int c = 0; c < M.cols(); ++c) buf[r * M.cols() + c] = M(r, c);
  val out = val::global("Float64Array").new_(buf.size());
  out.call<void>("set", val(emscripten::typed_memory_view(buf.size(), buf.data())));
  return out;
}

val to_uint32_array(const Eigen::MatrixXi& M) {
  std::vector<uint32_t> buf(M.size());
  for (int r = 0; r < M.rows(); ++r)
    for (int c = 0; c < M.cols(); ++c) buf[r * M.cols() + c] = static_cast<uint32_t>(M(r, c));
  val out = val::global("Uint32Array").new_(buf.size());
  out.call<void>("set", val(emscripten::typed_memory_view(buf.size(), buf.data())));
  return out;
}

val to_uint8_array(const std::vector<uint8_t>& bytes) {
  val out = val::global("Uint8Array").new_(bytes.size());
  out.call<void>("set", val(emscripten::typed_memory_view(bytes.size(), bytes.data())));
  return out;
}

double get_number(const val& obj, const char* name, double fallback) {
  if (obj.isUndefined() || obj.isNull()) return fallback;
  const val v = obj[name];
  if (v.isUndefined() || v.isNull() || !v.isNumber()) return fallback;
  return v.as<double>();
}

int get_int(const val& obj, const char* name, int fallback) {
  return static_cast<int>(get_number(obj, name, fallback));
}

bool get_bool(const val& obj, const char* name, bool fallback) {
  if (obj.isUndefined() || obj.isNull()) return fallback;
  const val v = obj[name];
  if (v.isUndefined() || v.isNull()) return fallback;
  return v.as<bool>();
}

std::string get_string(const val& obj, const char* name, const std::string& fallback) {
  if (obj.isUndefined() || obj.isNull()) return fallback;
  const val v = obj[name];
  if (!v.isString()) return fallback;
  return v.as<std::string>();
}

val status_object(const Status& s) {
  val o = val::object();
  o.set("ok", s.ok());
  if (!s.ok()) {
    o.set("code", std::string(status_code_name(s.code)));
    o.set("message", s.message);
  }
  return o;
}

val exception_object(const std::string& what, const std::exception* e, bool out_of_memory) {
  val o = val::object();
  o.set("ok", false);
  // OutOfMemory is a page-level code (web/src/errors.js); everything else escaping is a bug.
  o.set("code", std::string(out_of_memory ? "OutOfMemory" : "Internal"));
  std::string detail = e ? e->what() : "unknown exception";
  if (detail.size() > 200) detail = detail.substr(0, 200) + "...";
  o.set("message", out_of_memory ? what + ": out of memory (the input is too large for the browser's 4 GB)"
                                 : what + ": internal error: " + detail);
  return o;
}

Status read_js_option_value(const val& v, const std::string& key, app::OptionValue* out) {
  if (v.isNumber()) *out = app::OptionValue::of_number(v.as<double>());
  else if (v.isTrue() || v.isFalse()) *out = app::OptionValue::of_boolean(v.isTrue());
  else if (v.isString()) *out = app::OptionValue::of_text(v.as<std::string>());
  else return Status::error(StatusCode::InvalidArgument, "option " + key.substr(0, 60) + " must be a number, a string or a boolean");
  return Status::success();
}

std::vector<std::string> js_object_keys(const val& obj) {
  std::vector<std::string> keys;
  if (obj.isUndefined() || obj.isNull() || obj.typeOf().as<std::string>() != "object") return keys;
  const val k = val::global("Object").call<val>("keys", obj);
  const int n = k["length"].as<int>();
  for (int i = 0; i < n; ++i) keys.push_back(k[i].as<std::string>());
  return keys;
}

Progress js_progress(const val& callback) {
  if (callback.isUndefined() || callback.isNull()) return Progress();
  return Progress([callback](const std::string& stage, double f) {
    const val r = callback(stage, f);
    return r.isUndefined() || r.as<bool>();
  });
}

}  // namespace mm::wasm
