#include "io/off.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string_view>

#include "io/io_text.h"
#include "io/json_text.h"

namespace mm::io {

Status load_off(const std::vector<uint8_t>& bytes, Asset* asset) {
  using namespace detail;
  auto doc = std::make_shared<OffDocument>();
  TextLines reader(bytes.data(), bytes.size());
  std::string_view line;
  const std::string& name = asset->source_name;
  auto error = [&](StatusCode code, const std::string& what) {
    return Status::error(code, name + ": line " + std::to_string(reader.line_number()) + ": " + what);
  };
  // The next non-blank, non-comment line's tokens; comment lines before the counts are kept.
  bool in_header = true;
  auto next_tokens = [&](std::vector<std::string_view>* tok, std::string_view* stripped) {
    while (reader.next(&line)) {
      const std::string_view s = strip_comment(line, '#');
      if (s.empty()) {
        if (in_header && !line.empty()) doc->comments.emplace_back(line);
        continue;
      }
      *stripped = s;
      split_tokens(s, tok);
      return true;
    }
    return false;
  };
  std::vector<std::string_view> tok;
  std::string_view stripped;
  if (!next_tokens(&tok, &stripped))
    return Status::error(StatusCode::ParseError, name + ": OFF file has no header");
  const std::string_view kw = tok[0];
  const size_t off_pos = kw.rfind("OFF");
  if (off_pos == std::string_view::npos || off_pos + 3 != kw.size())
    return error(StatusCode::ParseError, "expected the header keyword 'OFF' (or COFF/NOFF), found '" +
                                             quote_input(kw) + "'");
  const std::string_view prefix = kw.substr(0, off_pos);
  for (char c : prefix)
    if (c != 'S' && c != 'T' && c != 'C' && c != 'N')
      return error(StatusCode::Unsupported, "OFF variant '" + quote_input(kw) +
                                                "' (4D or n-dimensional) is not supported");
  doc->keyword = quote_input(kw);
  size_t first = 1;
  if (tok.size() > 1 && tok[1] == "BINARY")
    return error(StatusCode::Unsupported, "binary OFF is not supported; save it as ASCII OFF or PLY");
  if (tok.size() == 1) {
    if (!next_tokens(&tok, &stripped)) return error(StatusCode::ParseError, "missing vertex/face counts");
    first = 0;
  }
  in_header = false;
  long long nv = -1, nf = -1;
  if (tok.size() < first + 2 || !parse_int_token(tok[first], &nv) || !parse_int_token(tok[first + 1], &nf) ||
      nv < 0 || nf < 0)
    return error(StatusCode::ParseError, "expected the vertex and face counts after 'OFF'");
  // A count is a claim, not an allocation size: the data has to back it (each vertex needs at
  // least 6 bytes of text, each face 8), so a lying header cannot make us reserve gigabytes.
  if (nv > static_cast<long long>(bytes.size() / 6) + 1 || nf > static_cast<long long>(bytes.size() / 8) + 1)
    return error(StatusCode::ParseError, "header declares " + std::to_string(nv) + " vertices and " +
                                             std::to_string(nf) + " faces, more than the file can hold");
  std::vector<double> v;
  v.reserve(static_cast<size_t>(nv) * 3);
  for (long long i = 0; i < nv; ++i) {
    if (!next_tokens(&tok, &stripped))
      return Status::error(StatusCode::ParseError, name + ": header declares " + std::to_string(nv) +
                                                       " vertices but the file ends after " +
                                                       std::to_string(i));
    if (tok.size() < 3) return error(StatusCode::ParseError, "vertex needs 3 coordinates");
    for (int c = 0; c < 3; ++c) {
      double x;
      if (!parse_double_token(tok[c], &x))
        return error(StatusCode::ParseError, "'" + quote_input(tok[c]) + "' is not a number");
      v.push_back(x);
    }
    const size_t rest = static_cast<size_t>(tok[2].data() + tok[2].size() - stripped.data());
    doc->vertex_extra.emplace_back(stripped.substr(rest));
  }
  std::vector<int> tri, poly;
  tri.reserve(static_cast<size_t>(nf) * 3);
  for (long long i = 0; i < nf; ++i) {
    if (!next_tokens(&tok, &stripped))
      return Status::error(StatusCode::ParseError, name + ": header declares " + std::to_string(nf) +
                                                       " faces but the file ends after " +
                                                       std::to_string(i));
    long long n = 0;
    if (!parse_int_token(tok[0], &n) || n < 0)
      return error(StatusCode::ParseError, "face must start with its corner count");
    if (n < 3) return error(StatusCode::ParseError, "face has " + std::to_string(n) + " corners (at least 3 needed)");
    if (n > static_cast<long long>(tok.size()) - 1)  // not n + 1: n may be LLONG_MAX
      return error(StatusCode::ParseError, "face declares " + std::to_string(n) + " corners but lists " +
                                               std::to_string(tok.size() - 1));
    poly.resize(static_cast<size_t>(n));
    for (long long c = 0; c < n; ++c) {
      long long k = 0;
      if (!parse_int_token(tok[1 + c], &k))
        return error(StatusCode::ParseError, "'" + quote_input(tok[1 + c]) + "' is not a vertex index");
      if (k < 0 || k >= nv)
        return error(StatusCode::ParseError, "face references vertex " + std::to_string(k) + " but there are " +
                                                 std::to_string(nv) + " vertices (indices start at 0)");
      poly[c] = static_cast<int>(k);
    }
    for (long long c = 1; c + 1 < n; ++c) {
      tri.push_back(poly[0]);
      tri.push_back(poly[c]);
      tri.push_back(poly[c + 1]);
    }
    doc->face_lines.emplace_back(stripped);
    doc->face_triangles.push_back(static_cast<int>(n - 2));
  }
  if (nv == 0) return Status::error(StatusCode::ParseError, name + ": OFF file declares 0 vertices");
  asset->V_raw = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(v.data(), nv, 3);
  asset->F_raw = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(tri.data(), tri.size() / 3, 3);
  asset->document = std::move(doc);
  return Status::success();
}

Status save_off_document(const OffDocument& doc, const Eigen::MatrixXd& V_raw_new,
                         std::vector<uint8_t>* out) {
  using namespace detail;
  assert(V_raw_new.rows() == static_cast<long>(doc.vertex_extra.size()) && "one position per vertex");
  out->clear();
  append_text(out, doc.keyword + "\n");
  for (const std::string& c : doc.comments) append_text(out, c + "\n");
  append_text(out, std::to_string(V_raw_new.rows()) + " " + std::to_string(doc.face_lines.size()) + " 0\n");
  for (int r = 0; r < V_raw_new.rows(); ++r)
    append_text(out, format_double(V_raw_new(r, 0)) + " " + format_double(V_raw_new(r, 1)) + " " +
                         format_double(V_raw_new(r, 2)) + doc.vertex_extra[r] + "\n");
  for (const std::string& f : doc.face_lines) append_text(out, f + "\n");
  return Status::success();
}

Status write_off(const ExportMesh& mesh, std::vector<uint8_t>* out) {
  using namespace detail;
  const bool has_c = mesh.C.rows() == mesh.V.rows() && mesh.C.rows() > 0;
  out->clear();
  append_text(out, has_c ? "COFF\n" : "OFF\n");
  append_text(out, std::to_string(mesh.V.rows()) + " " + std::to_string(mesh.F.rows()) + " 0\n");
  for (int r = 0; r < mesh.V.rows(); ++r) {
    std::string s = format_double(mesh.V(r, 0)) + " " + format_double(mesh.V(r, 1)) + " " +
                    format_double(mesh.V(r, 2));
    if (has_c)
      for (int c = 0; c < 3; ++c)
        s += " " + std::to_string(static_cast<int>(std::lround(std::clamp(mesh.C(r, c), 0.0, 1.0) * 255)));
    append_text(out, s + "\n");
  }
  for (int f = 0; f < mesh.F.rows(); ++f)
    append_text(out, "3 " + std::to_string(mesh.F(f, 0)) + " " + std::to_string(mesh.F(f, 1)) + " " +
                         std::to_string(mesh.F(f, 2)) + "\n");
  return Status::success();
}

}  // namespace mm::io
