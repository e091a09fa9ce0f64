#include "convert.h"

#include <memory>

#include <emscripten/bind.h>

namespace mm::wasm {

using emscripten::val;

namespace {
// A JS array (typed or plain) of length ≥ rows·cols read as a row-major rows × cols matrix of T:
// one `set` into the matrix's own storage (TypedArray.prototype.set converts each element with
// ToNumber and then to T: for int32, modulo 2^32, so 2^32 − 1 from a Uint32Array reads as −1,
// an out-of-range index the validation reports). Entries past rows·cols are ignored.
template <class T>
Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> read_row_major(const val& array, int cols) {
  if (array.isUndefined() || array.isNull()) return {};
  const size_t length = array["length"].as<size_t>();
  const int rows = static_cast<int>(length / static_cast<size_t>(cols));
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> R(rows, cols);
  const size_t used = static_cast<size_t>(rows) * static_cast<size_t>(cols);
  val(emscripten::typed_memory_view(used, R.data()))
      .call<void>("set", used == length ? array : array.call<val>("slice", 0, used));
  return R;
}
}  // namespace

Eigen::MatrixXd to_matrix(const val& array, int cols) { return read_row_major<double>(array, cols); }

Eigen::MatrixXi to_index_matrix(const val& array, int cols) { return read_row_major<int>(array, cols); }

std::vector<uint8_t> to_bytes(const val& array) {
  if (array.isUndefined() || array.isNull()) return {};
  return emscripten::convertJSArrayToNumberVector<uint8_t>(array);
}

std::vector<int> to_int_vector(const val& array) {
  if (array.isUndefined() || array.isNull()) return {};
  return emscripten::convertJSArrayToNumberVector<int>(array);
}

namespace {
// A new JS typed array of the named type holding a copy of data[0, n): `new T(view)` allocates
// and copies once (no zero-fill, no second pass); the view is only read during the call.
template <class T>
val copy_to_js(const char* type, const T* data, size_t n) {
  return val::global(type).new_(val(emscripten::typed_memory_view(n, data)));
}

// M's entries in row-major order, cast to T, in an uninitialised buffer (a std::vector would
// zero-fill it first: one more pass over fresh memory, which costs as much as the copy at 1M
// vertices).
template <class T, class Derived>
val row_major_to_js(const char* type, const Eigen::MatrixBase<Derived>& M) {
  using RowMajor = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::unique_ptr<T[]> buf(new T[static_cast<size_t>(M.size())]);
  Eigen::Map<RowMajor>(buf.get(), M.rows(), M.cols()) = M.template cast<T>();
  return copy_to_js(type, buf.get(), static_cast<size_t>(M.size()));
}
}  // namespace

val to_float32_array(const Eigen::MatrixXd& M) { return row_major_to_js<float>("Float32Array", M); }

val to_float64_array(const Eigen::MatrixXd& M) { return row_major_to_js<double>("Float64Array", M); }

val to_uint32_array(const Eigen::MatrixXi& M) { return row_major_to_js<uint32_t>("Uint32Array", M); }

val to_uint8_array(const std::vector<uint8_t>& bytes) { return copy_to_js("Uint8Array", bytes.data(), bytes.size()); }

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
