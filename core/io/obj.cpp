#include "io/obj.h"

#include <array>
#include <cassert>
#include <map>
#include <string_view>
#include <tuple>

#include "operators/operators.h"
#include "io/io_text.h"
#include "io/json_text.h"

namespace mm::io {

namespace detail {

// The part of `line` after its first `n` tokens (leading blanks included), so that write-back
// can keep whatever follows the coordinates (w, vertex colors, comments) verbatim.
static std::string_view obj_rest_after_tokens(std::string_view line, int n) {
  size_t i = 0;
  for (int t = 0; t < n; ++t) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
  }
  return line.substr(i);
}

// Resolves one OBJ index (1-based, or negative = relative to the end) against `count`
// elements defined so far. Returns -1 with *message set when invalid.
static int obj_resolve_index(std::string_view token, int count, const char* what, const char* plural, int line,
                             std::string* message) {
  long long k = 0;
  if (!parse_int_token(token, &k)) {
    *message = "line " + std::to_string(line) + ": '" + quote_input(token) +
               "' is not a valid " + what + " index";
    return -1;
  }
  if (k == 0) {
    *message = "line " + std::to_string(line) + ": face references " + what +
               " 0, but OBJ indices start at 1";
    return -1;
  }
  const long long idx = k > 0 ? k - 1 : count + k;
  if (idx < 0 || idx >= count) {
    *message = "line " + std::to_string(line) + ": face references " + what + " " +
               std::to_string(k) + " but only " + std::to_string(count) + " " +
               (count == 1 ? std::string(what) + " is" : std::string(plural) + " are") + " defined before it";
    return -1;
  }
  return static_cast<int>(idx);
}

}  // namespace detail

Status load_obj(const std::vector<uint8_t>& bytes, Asset* asset) {
  using namespace detail;
  auto doc = std::make_shared<ObjDocument>();
  TextLines reader(bytes.data(), bytes.size());
  std::vector<double> v, vt, vn;
  std::vector<int> tri, tri_vt, tri_vn;  // 3 per triangle
  std::string_view line;
  std::string message;
  int skipped_elements = 0;
  std::vector<std::string_view> tok;  // one line's tokens, storage reused
  while (reader.next(&line)) {
    const int line_no = reader.line_number();
    doc->lines.emplace_back(line);
    split_tokens(strip_comment(line, '#'), &tok);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    auto error = [&](const std::string& what) {
      return Status::error(StatusCode::ParseError, asset->source_name + ": line " +
                                                       std::to_string(line_no) + ": " + what);
    };
    if (key == "v" || key == "vn") {
      if (tok.size() < 4) return error(std::string("'") + quote_input(key) + "' needs 3 coordinates");
      double xyz[3];
      for (int c = 0; c < 3; ++c)
        if (!parse_double_token(tok[1 + c], &xyz[c]))
          return error("'" + quote_input(tok[1 + c]) + "' is not a number");
      auto& dst = key == "v" ? v : vn;
      dst.insert(dst.end(), xyz, xyz + 3);
      (key == "v" ? doc->v_line : doc->vn_line).push_back(static_cast<int>(doc->lines.size()) - 1);
    } else if (key == "vt") {
      if (tok.size() < 2) return error("'vt' needs at least 1 coordinate");
      double uv[2] = {0, 0};
      for (size_t c = 0; c < 2 && c + 1 < tok.size(); ++c)
        if (!parse_double_token(tok[1 + c], &uv[c]))
          return error("'" + quote_input(tok[1 + c]) + "' is not a number");
      vt.insert(vt.end(), uv, uv + 2);
    } else if (key == "f") {
      if (tok.size() < 4) return error("face has fewer than 3 corners");
      const int nv = static_cast<int>(v.size() / 3), nt = static_cast<int>(vt.size() / 2),
                nn = static_cast<int>(vn.size() / 3);
      std::vector<std::array<int, 3>> corners;
      for (size_t c = 1; c < tok.size(); ++c) {
        const std::string_view t = tok[c];
        const size_t s1 = t.find('/');
        const size_t s2 = s1 == std::string_view::npos ? s1 : t.find('/', s1 + 1);
        std::array<int, 3> k = {-1, -1, -1};
        k[0] = obj_resolve_index(t.substr(0, s1), nv, "vertex", "vertices", line_no, &message);
        if (k[0] < 0) return Status::error(StatusCode::ParseError, asset->source_name + ": " + message);
        if (s1 != std::string_view::npos) {
          const std::string_view b = t.substr(s1 + 1, s2 == std::string_view::npos ? s2 : s2 - s1 - 1);
          if (!b.empty()) {
            k[1] = obj_resolve_index(b, nt, "texture coordinate", "texture coordinates", line_no, &message);
            if (k[1] < 0) return Status::error(StatusCode::ParseError, asset->source_name + ": " + message);
          }
          if (s2 != std::string_view::npos) {
            const std::string_view n = t.substr(s2 + 1);
            if (!n.empty()) {
              k[2] = obj_resolve_index(n, nn, "normal", "normals", line_no, &message);
              if (k[2] < 0) return Status::error(StatusCode::ParseError, asset->source_name + ": " + message);
            }
          }
        }
        corners.push_back(k);
      }
      // Fan triangulation is exact for convex polygons, which is what OBJ exporters write.
      for (size_t c = 1; c + 1 < corners.size(); ++c)
        for (size_t idx : {size_t(0), c, c + 1}) {
          tri.push_back(corners[idx][0]);
          tri_vt.push_back(corners[idx][1]);
          tri_vn.push_back(corners[idx][2]);
        }
    } else if (key == "l" || key == "p") {
      ++skipped_elements;
    }
  }
  doc->crlf = reader.saw_crlf();
  if (v.empty())
    return Status::error(StatusCode::ParseError,
                         asset->source_name + ": OBJ file has no vertices ('v' lines)");
  if (skipped_elements > 0)
    asset->warnings.push_back(std::to_string(skipped_elements) +
                              " line/point elements ('l', 'p') were kept but not loaded");
  const int nv = static_cast<int>(v.size() / 3), nf = static_cast<int>(tri.size() / 3);
  asset->V_raw = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(v.data(), nv, 3);
  asset->F_raw = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(tri.data(), nf, 3);
  doc->F_vt = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(tri_vt.data(), nf, 3);
  doc->F_vn = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(tri_vn.data(), nf, 3);
  doc->VT = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(vt.data(), vt.size() / 2, 2);
  doc->VN = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(vn.data(), vn.size() / 3, 3);
  asset->document = std::move(doc);
  return Status::success();
}

Status save_obj_document(const ObjDocument& doc, const Eigen::MatrixXi& F_raw,
                         const Eigen::MatrixXd& V_raw_new, bool positions_changed,
                         const SaveOptions& opt, std::vector<uint8_t>* out) {
  using namespace detail;
  assert(V_raw_new.rows() == static_cast<long>(doc.v_line.size()) && "one position per 'v'");
  std::vector<int> v_of_line(doc.lines.size(), -1), vn_of_line(doc.lines.size(), -1);
  for (size_t k = 0; k < doc.v_line.size(); ++k) v_of_line[doc.v_line[k]] = static_cast<int>(k);
  for (size_t k = 0; k < doc.vn_line.size(); ++k) vn_of_line[doc.vn_line[k]] = static_cast<int>(k);
  Eigen::MatrixXd N;
  const bool new_normals = opt.recompute_normals && positions_changed && doc.VN.rows() > 0;
  if (new_normals) N = grouped_vertex_normals(V_raw_new, F_raw, doc.F_vn, static_cast<int>(doc.VN.rows()));
  const char* eol = doc.crlf ? "\r\n" : "\n";
  out->clear();
  for (size_t i = 0; i < doc.lines.size(); ++i) {
    const std::string& line = doc.lines[i];
    if (v_of_line[i] >= 0) {
      const int k = v_of_line[i];
      append_text(out, "v " + format_double(V_raw_new(k, 0)) + " " + format_double(V_raw_new(k, 1)) +
                           " " + format_double(V_raw_new(k, 2)));
      append_text(out, obj_rest_after_tokens(line, 4));
    } else if (vn_of_line[i] >= 0 && new_normals && N.row(vn_of_line[i]).squaredNorm() > 0) {
      const int k = vn_of_line[i];
      append_text(out, "vn " + format_double(N(k, 0)) + " " + format_double(N(k, 1)) + " " +
                           format_double(N(k, 2)));
      append_text(out, obj_rest_after_tokens(line, 4));
    } else {
      append_text(out, line);
    }
    append_text(out, eol);
  }
  return Status::success();
}

ExportMesh obj_export_mesh(const ObjDocument& doc, const Eigen::MatrixXi& F_raw,
                           const Eigen::MatrixXd& V_raw_new, bool recompute_normals) {
  ExportMesh m;
  const bool has_vt = doc.F_vt.size() > 0 && doc.F_vt.maxCoeff() >= 0;
  const bool has_vn = doc.F_vn.size() > 0 && doc.F_vn.maxCoeff() >= 0;
  if (!has_vt && !has_vn) {
    m.V = V_raw_new;
    m.F = F_raw;
    return m;
  }
  Eigen::MatrixXd VN = doc.VN;
  if (has_vn && recompute_normals) {
    const Eigen::MatrixXd R = grouped_vertex_normals(V_raw_new, F_raw, doc.F_vn, static_cast<int>(VN.rows()));
    for (int k = 0; k < VN.rows(); ++k)
      if (R.row(k).squaredNorm() > 0) VN.row(k) = R.row(k);
  }
  // Vertices are split per distinct (v, vt, vn) corner, numbered in order of first use.
  std::map<std::tuple<int, int, int>, int> id;
  std::vector<std::tuple<int, int, int>> keys;
  m.F.resize(F_raw.rows(), 3);
  for (int f = 0; f < F_raw.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const auto key = std::make_tuple(F_raw(f, c), doc.F_vt(f, c), doc.F_vn(f, c));
      auto it = id.emplace(key, static_cast<int>(keys.size())).first;
      if (it->second == static_cast<int>(keys.size())) keys.push_back(key);
      m.F(f, c) = it->second;
    }
  const int n = static_cast<int>(keys.size());
  m.V.resize(n, 3);
  if (has_vt) m.UV = Eigen::MatrixXd::Zero(n, 2);
  if (has_vn) m.N = Eigen::MatrixXd::Zero(n, 3);
  for (int k = 0; k < n; ++k) {
    const auto [vi, ti, ni] = keys[k];
    m.V.row(k) = V_raw_new.row(vi);
    if (has_vt && ti >= 0) m.UV.row(k) << doc.VT(ti, 0), 1.0 - doc.VT(ti, 1);
    if (has_vn && ni >= 0) m.N.row(k) = VN.row(ni).normalized();
  }
  return m;
}

Status write_obj(const ExportMesh& mesh, std::vector<uint8_t>* out) {
  using namespace detail;
  out->clear();
  append_text(out, "# written by MeshMorph\n");
  auto row3 = [](const char* key, const Eigen::MatrixXd& M, int r) {
    return quote_input(key) + " " + format_double(M(r, 0)) + " " + format_double(M(r, 1)) + " " +
           format_double(M(r, 2));
  };
  const bool has_c = mesh.C.rows() == mesh.V.rows() && mesh.C.rows() > 0;
  for (int r = 0; r < mesh.V.rows(); ++r) {
    // Vertex colors as the common `v x y z r g b` extension (read by MeshLab, Blender).
    std::string s = row3("v", mesh.V, r);
    if (has_c) s += " " + format_double(mesh.C(r, 0)) + " " + format_double(mesh.C(r, 1)) + " " +
                    format_double(mesh.C(r, 2));
    append_text(out, s + "\n");
  }
  const bool has_uv = mesh.UV.rows() == mesh.V.rows() && mesh.UV.rows() > 0;
  const bool has_n = mesh.N.rows() == mesh.V.rows() && mesh.N.rows() > 0;
  if (has_uv)
    for (int r = 0; r < mesh.UV.rows(); ++r)
      append_text(out, "vt " + format_double(mesh.UV(r, 0)) + " " + format_double(1.0 - mesh.UV(r, 1)) + "\n");
  if (has_n)
    for (int r = 0; r < mesh.N.rows(); ++r) append_text(out, row3("vn", mesh.N, r) + "\n");
  for (int f = 0; f < mesh.F.rows(); ++f) {
    std::string s = "f";
    for (int c = 0; c < 3; ++c) {
      const std::string k = std::to_string(mesh.F(f, c) + 1);
      s += " " + k;
      if (has_uv && has_n) s += "/" + k + "/" + k;
      else if (has_uv) s += "/" + k;
      else if (has_n) s += "//" + k;
    }
    append_text(out, s + "\n");
  }
  return Status::success();
}

}  // namespace mm::io
