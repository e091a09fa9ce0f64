#include "io/ply.h"

#include <algorithm>
#include <cctype>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string_view>

#include "operators/operators.h"
#include "io/io_text.h"
#include "io/json_text.h"

namespace mm::io {

int PlyElement::find(const std::string& property) const {
  for (size_t i = 0; i < properties.size(); ++i)
    if (properties[i].name == property) return static_cast<int>(i);
  return -1;
}

namespace detail {

static bool ply_type_from_name(std::string_view s, PlyType* t) {
  struct Entry { const char* name; PlyType type; };
  static const Entry table[] = {
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},   {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16}, {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},   {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const Entry& e : table)
    if (s == e.name) {
      *t = e.type;
      return true;
    }
  return false;
}

static size_t ply_type_size(PlyType t) {
  switch (t) {
    case PlyType::Int8: case PlyType::UInt8: return 1;
    case PlyType::Int16: case PlyType::UInt16: return 2;
    case PlyType::Int32: case PlyType::UInt32: case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 1;
}

static bool ply_is_integer_type(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

// Decodes one binary value; the caller guarantees ply_type_size(t) readable bytes.
static double ply_decode(const uint8_t* p, PlyType t, bool big_endian) {
  uint8_t b[8];
  const size_t n = ply_type_size(t);
  for (size_t i = 0; i < n; ++i) b[i] = big_endian ? p[n - 1 - i] : p[i];
  // The host is little-endian on every target we build (x86-64, wasm32).
  switch (t) {
    case PlyType::Int8: { int8_t v; std::memcpy(&v, b, 1); return v; }
    case PlyType::UInt8: return b[0];
    case PlyType::Int16: { int16_t v; std::memcpy(&v, b, 2); return v; }
    case PlyType::UInt16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
    case PlyType::Int32: { int32_t v; std::memcpy(&v, b, 4); return v; }
    case PlyType::UInt32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
    case PlyType::Float32: { float v; std::memcpy(&v, b, 4); return v; }
    case PlyType::Float64: { double v; std::memcpy(&v, b, 8); return v; }
  }
  return 0;
}

// The range of an integer PLY type.
static void ply_integer_range(PlyType t, double* lo, double* hi) {
  switch (t) {
    case PlyType::Int8: *lo = INT8_MIN, *hi = INT8_MAX; return;
    case PlyType::UInt8: *lo = 0, *hi = UINT8_MAX; return;
    case PlyType::Int16: *lo = INT16_MIN, *hi = INT16_MAX; return;
    case PlyType::UInt16: *lo = 0, *hi = UINT16_MAX; return;
    case PlyType::Int32: *lo = INT32_MIN, *hi = INT32_MAX; return;
    case PlyType::UInt32: *lo = 0, *hi = UINT32_MAX; return;
    default: *lo = -HUGE_VAL, *hi = HUGE_VAL; return;
  }
}

// A value written into an integer property: in the type's range (a cast of an out-of-range double
// is undefined behaviour). Read values are range-checked already; this guards computed positions
// written into integer x/y/z.
static double ply_clamp_to_type(double value, PlyType t) {
  if (!ply_is_integer_type(t)) return value;
  if (std::isnan(value)) return 0;
  double lo, hi;
  ply_integer_range(t, &lo, &hi);
  return std::min(hi, std::max(lo, value));
}

static void ply_encode(double value, PlyType t, bool big_endian, std::vector<uint8_t>* out) {
  uint8_t b[8];
  const size_t n = ply_type_size(t);
  value = ply_clamp_to_type(value, t);
  switch (t) {
    case PlyType::Int8: { const int8_t v = static_cast<int8_t>(value); std::memcpy(b, &v, 1); break; }
    case PlyType::UInt8: { const uint8_t v = static_cast<uint8_t>(value); std::memcpy(b, &v, 1); break; }
    case PlyType::Int16: { const int16_t v = static_cast<int16_t>(value); std::memcpy(b, &v, 2); break; }
    case PlyType::UInt16: { const uint16_t v = static_cast<uint16_t>(value); std::memcpy(b, &v, 2); break; }
    case PlyType::Int32: { const int32_t v = static_cast<int32_t>(value); std::memcpy(b, &v, 4); break; }
    case PlyType::UInt32: { const uint32_t v = static_cast<uint32_t>(value); std::memcpy(b, &v, 4); break; }
    case PlyType::Float32: { const float v = static_cast<float>(value); std::memcpy(b, &v, 4); break; }
    case PlyType::Float64: std::memcpy(b, &value, 8); break;
  }
  for (size_t i = 0; i < n; ++i) out->push_back(big_endian ? b[n - 1 - i] : b[i]);
}

static std::string ply_format_value(double value, PlyType t) {
  if (ply_is_integer_type(t)) return std::to_string(static_cast<long long>(ply_clamp_to_type(value, t)));
  if (t == PlyType::Float64) return format_double(value);
  if (value == 0) return "0";  // folds -0, like format_double
  // Shortest text that reads back as the same float.
  const float f = static_cast<float>(value);
  if (std::isnan(f) || std::isinf(f)) return format_double(f);
  char buf[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buf, sizeof(buf), "%.*g", digits, static_cast<double>(f));
    if (std::strtof(buf, nullptr) == f) break;
  }
  return buf;
}

// Reads the data section into the elements' columns. Binary and ASCII share the loop; ASCII
// is read as a token stream, which also accepts elements split or joined across lines.
class PlyDataReader {
 public:
  PlyDataReader(const uint8_t* data, size_t size, PlyEncoding enc)
      : data_(data), size_(size), enc_(enc) {}

  // Small enough to inline into the element loop: the binary little-endian case (most files)
  // decodes in place; ASCII and big-endian go through the out-of-line readers.
  bool read(PlyType t, double* v) {
    if (enc_ == PlyEncoding::BinaryLittleEndian) {
      const size_t n = ply_type_size(t);
      if (size_ - pos_ < n) return false;
      const uint8_t* p = data_ + pos_;
      pos_ += n;
      switch (t) {
        case PlyType::Int8: *v = static_cast<int8_t>(p[0]); return true;
        case PlyType::UInt8: *v = p[0]; return true;
        case PlyType::Int16: { int16_t x; std::memcpy(&x, p, 2); *v = x; return true; }
        case PlyType::UInt16: { uint16_t x; std::memcpy(&x, p, 2); *v = x; return true; }
        case PlyType::Int32: { int32_t x; std::memcpy(&x, p, 4); *v = x; return true; }
        case PlyType::UInt32: { uint32_t x; std::memcpy(&x, p, 4); *v = x; return true; }
        case PlyType::Float32: { float x; std::memcpy(&x, p, 4); *v = x; return true; }
        case PlyType::Float64: { std::memcpy(v, p, 8); return true; }
      }
      return false;
    }
    return enc_ == PlyEncoding::Ascii ? read_ascii(t, v) : read_big_endian(t, v);
  }
  size_t remaining() const { return size_ - pos_; }
  const std::string& bad_token() const { return bad_token_; }
  const std::string& bad_kind() const { return bad_kind_; }

 private:
  bool read_ascii(PlyType t, double* v) {
    while (pos_ < size_ && std::isspace(data_[pos_])) ++pos_;
    const size_t b = pos_;
    while (pos_ < size_ && !std::isspace(data_[pos_])) ++pos_;
    if (pos_ == b) return false;
    const std::string_view tok(reinterpret_cast<const char*>(data_) + b, pos_ - b);
    if (!parse_double_token(tok, v)) {
      bad_token_ = quote_input(tok);
      return false;
    }
    // An integer property holds an integer of its type's range (binary data cannot do otherwise).
    if (ply_is_integer_type(t)) {
      double lo, hi;
      ply_integer_range(t, &lo, &hi);
      if (!(*v >= lo && *v <= hi && *v == std::floor(*v))) {
        bad_token_ = quote_input(tok);
        bad_kind_ = " is not an integer of the property's type";
        return false;
      }
    }
    return true;
  }
  bool read_big_endian(PlyType t, double* v) {
    const size_t n = ply_type_size(t);
    if (size_ - pos_ < n) return false;
    *v = ply_decode(data_ + pos_, t, true);
    pos_ += n;
    return true;
  }

  const uint8_t* data_;
  size_t size_;
  PlyEncoding enc_;
  size_t pos_ = 0;
  std::string bad_token_;
  std::string bad_kind_ = " is not a number";
};

}  // namespace detail

Status load_ply(const std::vector<uint8_t>& bytes, Asset* asset) {
  using namespace detail;
  const std::string& name = asset->source_name;
  auto fail = [&](StatusCode code, const std::string& what) {
    return Status::error(code, name + ": " + what);
  };
  // Element and property names are the file's own text: quoted short in messages (kept whole in the document).
  auto quoted = [](const std::string& n) { return quote_input(n, 60); };
  auto doc = std::make_shared<PlyDocument>();
  TextLines reader(bytes.data(), bytes.size());
  std::string_view line;
  if (!reader.next(&line) || strip_comment(line, '\0') != "ply")
    return fail(StatusCode::ParseError, "not a PLY file (the first line must be 'ply')");
  bool have_format = false, have_end = false;
  while (reader.next(&line)) {
    const std::vector<std::string_view> tok = split_tokens(line);
    const auto where = [&] { return "header line " + std::to_string(reader.line_number()) + ": "; };
    if (tok.empty()) continue;
    if (tok[0] == "end_header") {
      have_end = true;
      break;
    }
    if (tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      if (tok.size() < 3) return fail(StatusCode::ParseError, where() + "incomplete 'format' line");
      if (tok[1] == "ascii") doc->encoding = PlyEncoding::Ascii;
      else if (tok[1] == "binary_little_endian") doc->encoding = PlyEncoding::BinaryLittleEndian;
      else if (tok[1] == "binary_big_endian") doc->encoding = PlyEncoding::BinaryBigEndian;
      else return fail(StatusCode::Unsupported, where() + "unknown PLY format '" + quote_input(tok[1]) + "'");
      have_format = true;
    } else if (tok[0] == "element") {
      long long count = -1;
      if (tok.size() < 3 || !parse_int_token(tok[2], &count) || count < 0)
        return fail(StatusCode::ParseError, where() + "'element' needs a name and a count");
      PlyElement e;
      e.name = std::string(tok[1]);
      e.count = static_cast<size_t>(count);
      doc->elements.push_back(std::move(e));
    } else if (tok[0] == "property") {
      if (doc->elements.empty()) return fail(StatusCode::ParseError, where() + "'property' before any 'element'");
      PlyProperty p;
      if (tok.size() >= 2 && tok[1] == "list") {
        if (tok.size() < 5 || !ply_type_from_name(tok[2], &p.count_type) || !ply_type_from_name(tok[3], &p.type))
          return fail(StatusCode::ParseError, where() + "malformed list property '" + quote_input(line) + "'");
        if (!ply_is_integer_type(p.count_type))
          return fail(StatusCode::ParseError, where() + "list count type must be an integer type");
        p.is_list = true;
        p.name = std::string(tok[4]);
      } else {
        if (tok.size() < 3 || !ply_type_from_name(tok[1], &p.type))
          return fail(StatusCode::ParseError, where() + "malformed property '" + quote_input(line) + "'");
        p.name = std::string(tok[2]);
      }
      doc->elements.back().properties.push_back(std::move(p));
    } else {
      return fail(StatusCode::ParseError, where() + "unknown header keyword '" + quote_input(tok[0]) + "'");
    }
  }
  if (!have_end) return fail(StatusCode::ParseError, "PLY header has no 'end_header' line");
  if (!have_format) return fail(StatusCode::ParseError, "PLY header has no 'format' line");
  const size_t data_begin = reader.offset();
  doc->header.assign(reinterpret_cast<const char*>(bytes.data()), data_begin);

  PlyDataReader data(bytes.data() + data_begin, bytes.size() - data_begin, doc->encoding);
  for (PlyElement& e : doc->elements) {
    // An element without properties occupies no bytes; looping over its count could hang.
    if (e.properties.empty()) continue;
    // Refuse counts the remaining bytes cannot hold before allocating anything for them.
    size_t min_row = 0;
    for (const PlyProperty& p : e.properties)
      min_row += doc->encoding == PlyEncoding::Ascii ? 2 : ply_type_size(p.is_list ? p.count_type : p.type);
    if (min_row > 0 && e.count > data.remaining() / min_row + 1)
      return fail(StatusCode::ParseError, "PLY header declares " + std::to_string(e.count) + " " + quoted(e.name) +
                                              " elements but the data is too short to hold them");
    for (PlyProperty& p : e.properties) {
      if (p.is_list) {
        // Triangles, mostly; never more items than the remaining bytes can hold.
        const size_t item = doc->encoding == PlyEncoding::Ascii ? 2 : ply_type_size(p.type);
        p.offsets.reserve(e.count + 1), p.offsets.push_back(0);
        p.values.reserve(std::min(3 * e.count, data.remaining() / std::max<size_t>(1, item)));
      } else {
        p.values.reserve(e.count);
      }
    }
    for (size_t r = 0; r < e.count; ++r) {
      for (PlyProperty& p : e.properties) {
        auto truncated = [&] {
          if (!data.bad_token().empty())
            return fail(StatusCode::ParseError, "'" + data.bad_token() + "'" + data.bad_kind() + " (" + quoted(e.name) + " " +
                                                    std::to_string(r) + ", property " + quoted(p.name) + ")");
          return fail(StatusCode::ParseError, "PLY header declares " + std::to_string(e.count) + " " + quoted(e.name) +
                                                  " elements but the data ends at " + quoted(e.name) + " " +
                                                  std::to_string(r));
        };
        double v = 0;
        if (!p.is_list) {
          if (!data.read(p.type, &v)) return truncated();
          p.values.push_back(v);
          continue;
        }
        double n = 0;
        if (!data.read(p.count_type, &n)) return truncated();
        if (n < 0 || n != std::floor(n) || n > 1e6)
          return fail(StatusCode::ParseError, "invalid list length " + format_double(n) + " in " + quoted(e.name) + " " +
                                                  std::to_string(r));
        for (int k = 0; k < static_cast<int>(n); ++k) {
          if (!data.read(p.type, &v)) return truncated();
          p.values.push_back(v);
        }
        if (p.values.size() > UINT32_MAX) return fail(StatusCode::Unsupported, "PLY list data too large");
        p.offsets.push_back(static_cast<uint32_t>(p.values.size()));
      }
    }
  }
  if (doc->encoding != PlyEncoding::Ascii && data.remaining() > 0)
    asset->warnings.push_back(std::to_string(data.remaining()) + " bytes after the last PLY element were ignored");

  for (size_t i = 0; i < doc->elements.size(); ++i) {
    if (doc->elements[i].name == "vertex" && doc->vertex_element < 0) doc->vertex_element = static_cast<int>(i);
    if (doc->elements[i].name == "face" && doc->face_element < 0) doc->face_element = static_cast<int>(i);
  }
  if (doc->vertex_element < 0) return fail(StatusCode::ParseError, "PLY file has no 'vertex' element");
  const PlyElement& ve = doc->elements[doc->vertex_element];
  const int px = ve.find("x"), py = ve.find("y"), pz = ve.find("z");
  if (px < 0 || py < 0 || pz < 0 || ve.properties[px].is_list || ve.properties[py].is_list ||
      ve.properties[pz].is_list)
    return fail(StatusCode::ParseError, "PLY 'vertex' element needs scalar properties x, y and z");
  const int nv = static_cast<int>(ve.count);
  if (nv == 0) return fail(StatusCode::ParseError, "PLY file has 0 vertices");
  asset->V_raw.resize(nv, 3);
  for (int r = 0; r < nv; ++r)
    asset->V_raw.row(r) << ve.properties[px].values[r], ve.properties[py].values[r], ve.properties[pz].values[r];

  if (doc->face_element >= 0) {
    const PlyElement& fe = doc->elements[doc->face_element];
    doc->face_list = fe.find("vertex_indices");
    if (doc->face_list < 0) doc->face_list = fe.find("vertex_index");
    if (doc->face_list < 0 || !fe.properties[doc->face_list].is_list)
      return fail(StatusCode::ParseError, "PLY 'face' element needs a list property 'vertex_indices'");
    const PlyProperty& L = fe.properties[doc->face_list];
    // Checked and counted first, then written straight into F_raw (fans of polygons).
    size_t triangles = 0;
    for (size_t f = 0; f < fe.count; ++f) {
      const uint32_t b = L.offsets[f], n = L.offsets[f + 1] - b;
      if (n < 3)
        return fail(StatusCode::ParseError, "face " + std::to_string(f) + " has " + std::to_string(n) +
                                                " corners (at least 3 needed)");
      for (uint32_t k = 0; k < n; ++k) {
        const double idx = L.values[b + k];
        if (!(idx >= 0 && idx < nv) || idx != std::floor(idx))
          return fail(StatusCode::ParseError, "face " + std::to_string(f) + " references vertex " +
                                                  format_double(idx) + " but there are " + std::to_string(nv) +
                                                  " vertices");
      }
      triangles += n - 2;
    }
    if (triangles > static_cast<size_t>(std::numeric_limits<int>::max()))
      return fail(StatusCode::Unsupported, "PLY file has more than 2^31 triangles");
    Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> T(static_cast<Eigen::Index>(triangles), 3);
    Eigen::Index t = 0;
    for (size_t f = 0; f < fe.count; ++f) {
      const uint32_t b = L.offsets[f], n = L.offsets[f + 1] - b;
      for (uint32_t k = 1; k + 1 < n; ++k, ++t)
        T.row(t) << static_cast<int>(L.values[b]), static_cast<int>(L.values[b + k]), static_cast<int>(L.values[b + k + 1]);
    }
    asset->F_raw = T;
  } else {
    asset->warnings.push_back("PLY file has no 'face' element (point cloud)");
    asset->F_raw.resize(0, 3);
  }
  asset->document = std::move(doc);
  return Status::success();
}

namespace detail {

// Per-vertex normals of a PLY mesh: every vertex is its own normal group.
static Eigen::MatrixXd ply_vertex_normals(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  return grouped_vertex_normals(V, F, F, static_cast<int>(V.rows()));
}

}  // namespace detail

Status save_ply_document(const PlyDocument& doc, const Eigen::MatrixXi& F_raw,
                         const Eigen::MatrixXd& V_raw_new, bool positions_changed,
                         const SaveOptions& opt, std::vector<uint8_t>* out) {
  using namespace detail;
  const PlyElement& ve0 = doc.elements[doc.vertex_element];
  assert(V_raw_new.rows() == static_cast<long>(ve0.count) && "one position per PLY vertex");
  // Copy the vertex columns we change; everything else is written from the document.
  std::vector<std::vector<double>> replaced(ve0.properties.size());
  const char* axes[3] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c) {
    const int p = ve0.find(axes[c]);
    replaced[p].assign(V_raw_new.col(c).data(), V_raw_new.col(c).data() + V_raw_new.rows());
  }
  const char* naxes[3] = {"nx", "ny", "nz"};
  const int pn[3] = {ve0.find("nx"), ve0.find("ny"), ve0.find("nz")};
  if (opt.recompute_normals && positions_changed && pn[0] >= 0 && pn[1] >= 0 && pn[2] >= 0) {
    const Eigen::MatrixXd N = ply_vertex_normals(V_raw_new, F_raw);
    for (int c = 0; c < 3; ++c) {
      const PlyProperty& p = ve0.properties[pn[c]];
      if (p.is_list || ply_is_integer_type(p.type)) continue;
      replaced[pn[c]] = p.values;
      for (int r = 0; r < N.rows(); ++r)
        if (N.row(r).squaredNorm() > 0) replaced[pn[c]][r] = N(r, c);
    }
    (void)naxes;
  }
  out->clear();
  append_text(out, doc.header);
  const bool big = doc.encoding == PlyEncoding::BinaryBigEndian;
  const bool ascii = doc.encoding == PlyEncoding::Ascii;
  for (size_t ei = 0; ei < doc.elements.size(); ++ei) {
    const PlyElement& e = doc.elements[ei];
    const bool is_vertex = static_cast<int>(ei) == doc.vertex_element;
    // Rows without properties hold no bytes (the reader skips them too); a huge count must not loop.
    if (e.properties.empty()) continue;
    for (size_t r = 0; r < e.count; ++r) {
      std::string line;
      for (size_t pi = 0; pi < e.properties.size(); ++pi) {
        const PlyProperty& p = e.properties[pi];
        auto put = [&](double v, PlyType t) {
          if (ascii) {
            if (!line.empty()) line += ' ';
            line += ply_format_value(v, t);
          } else {
            ply_encode(v, t, big, out);
          }
        };
        if (p.is_list) {
          const uint32_t b = p.offsets[r], n = p.offsets[r + 1] - b;
          put(n, p.count_type);
          for (uint32_t k = 0; k < n; ++k) put(p.values[b + k], p.type);
        } else if (is_vertex && !replaced[pi].empty()) {
          put(replaced[pi][r], p.type);
        } else {
          put(p.values[r], p.type);
        }
      }
      if (ascii) append_text(out, line + "\n");
    }
  }
  return Status::success();
}

ExportMesh ply_export_mesh(const PlyDocument& doc, const Eigen::MatrixXi& F_raw,
                           const Eigen::MatrixXd& V_raw_new, bool recompute_normals) {
  using namespace detail;
  ExportMesh m;
  m.V = V_raw_new;
  m.F = F_raw;
  const PlyElement& ve = doc.elements[doc.vertex_element];
  const int pn[3] = {ve.find("nx"), ve.find("ny"), ve.find("nz")};
  if (pn[0] >= 0 && pn[1] >= 0 && pn[2] >= 0) {
    m.N.resize(V_raw_new.rows(), 3);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < m.N.rows(); ++r) m.N(r, c) = ve.properties[pn[c]].values[r];
    if (recompute_normals) {
      const Eigen::MatrixXd N = ply_vertex_normals(V_raw_new, F_raw);
      for (int r = 0; r < N.rows(); ++r)
        if (N.row(r).squaredNorm() > 0) m.N.row(r) = N.row(r);
    }
  }
  const int pc[3] = {ve.find("red"), ve.find("green"), ve.find("blue")};
  if (pc[0] >= 0 && pc[1] >= 0 && pc[2] >= 0) {
    m.C.resize(V_raw_new.rows(), 3);
    for (int c = 0; c < 3; ++c) {
      const PlyProperty& p = ve.properties[pc[c]];
      // Integer colors are 0..255 by convention, float colors 0..1.
      const double scale = ply_is_integer_type(p.type) ? 1.0 / 255.0 : 1.0;
      for (int r = 0; r < m.C.rows(); ++r) m.C(r, c) = std::clamp(p.values[r] * scale, 0.0, 1.0);
    }
  }
  return m;
}

Status write_ply(const ExportMesh& mesh, std::vector<uint8_t>* out) {
  using namespace detail;
  const bool has_n = mesh.N.rows() == mesh.V.rows() && mesh.N.rows() > 0;
  const bool has_c = mesh.C.rows() == mesh.V.rows() && mesh.C.rows() > 0;
  out->clear();
  std::string h = "ply\nformat binary_little_endian 1.0\ncomment written by MeshMorph\n";
  h += "element vertex " + std::to_string(mesh.V.rows()) + "\n";
  h += "property float x\nproperty float y\nproperty float z\n";
  if (has_n) h += "property float nx\nproperty float ny\nproperty float nz\n";
  if (has_c) h += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  h += "element face " + std::to_string(mesh.F.rows()) + "\n";
  h += "property list uchar int vertex_indices\nend_header\n";
  append_text(out, h);
  for (int r = 0; r < mesh.V.rows(); ++r) {
    for (int c = 0; c < 3; ++c) ply_encode(mesh.V(r, c), PlyType::Float32, false, out);
    if (has_n)
      for (int c = 0; c < 3; ++c) ply_encode(mesh.N(r, c), PlyType::Float32, false, out);
    if (has_c)
      for (int c = 0; c < 3; ++c)
        ply_encode(std::lround(std::clamp(mesh.C(r, c), 0.0, 1.0) * 255.0), PlyType::UInt8, false, out);
  }
  for (int f = 0; f < mesh.F.rows(); ++f) {
    ply_encode(3, PlyType::UInt8, false, out);
    for (int c = 0; c < 3; ++c) ply_encode(mesh.F(f, c), PlyType::Int32, false, out);
  }
  return Status::success();
}

}  // namespace mm::io
