// What each libFuzzer harness does with one input, shared with tests/io_fuzz_regressions_test.cpp
// (which replays tests/bad/<harness>/ through the same functions). Each calls the entry points the
// CLI and the page use and returns the reader's Status; what must never happen aborts, so that
// libFuzzer keeps the input: a Status with an unknown code, an error without a message or with one
// over 1 KiB (issue 13 caps quoted input at ~100 bytes), or a "success" whose result is inconsistent.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "app/edit_spec.h"
#include "app/merge_job.h"
#include "common/status.h"
#include "io/asset.h"
#include "io/gltf_animation.h"
#include "io/info_report.h"
#include "io/joints_json.h"
#include "io/landmarks_file.h"

namespace mm::fuzz {

constexpr size_t kMaxMessage = 1024;

[[noreturn]] inline void violated(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz invariant violated in %s: %.300s\n", what, detail.c_str());
  std::abort();
}

inline const Status& checked(const Status& s, const char* what) {
  const int code = static_cast<int>(s.code);
  if (code < static_cast<int>(StatusCode::Ok) || code > static_cast<int>(StatusCode::Cancelled))
    violated(what, "status code " + std::to_string(code) + " out of range");
  if (s.ok() && !s.message.empty()) violated(what, "success with a message: " + s.message);
  if (!s.ok() && s.message.empty()) violated(what, std::string("error ") + status_code_name(s.code) + " without a message");
  if (s.message.size() > kMaxMessage) violated(what, std::to_string(s.message.size()) + "-byte message: " + s.message);
  return s;
}

// Mesh files as `meshmorph info` / `convert` and the page's loadAsset read them:
// io::load_asset_from_memory (load_asset is read_file + this), then on success the info report, a
// save in the same format (convert) and, for glTF, the animated character (retarget).
inline Status read_mesh(io::Format format, const std::vector<uint8_t>& bytes) {
  // A .gltf's sibling files: "buffer.bin" exists (64 bytes), anything else is missing. The CLI
  // reads siblings from the file's folder, the page from the dropped files; both come through here.
  const io::FileResolver resolver = [](const std::string& uri, std::vector<uint8_t>* out) {
    if (uri != "buffer.bin") return false;
    out->assign(64, 0);
    for (size_t i = 0; i < out->size(); ++i) (*out)[i] = static_cast<uint8_t>(i * 37);
    return true;
  };
  const io::LoadResult r = io::load_asset_from_memory(bytes, format, "fuzz", resolver);
  if (!checked(r.status, "load").ok()) return r.status;
  const io::Asset& a = r.asset;
  if (a.F_raw.cols() != 3 || a.V_raw.cols() != 3 || a.weld.V.cols() != 3) violated("load", "matrix shape");
  if (a.F_raw.size() > 0 && (a.F_raw.minCoeff() < 0 || a.F_raw.maxCoeff() >= a.V_raw.rows()))
    violated("load", "face index out of range");
  if (io::info_report(a).json.empty()) violated("info", "empty report");
  std::vector<uint8_t> out;
  checked(io::save_asset_to_memory(a, a.weld.V, a.format, &out), "save");
  if (format == io::Format::Gltf || format == io::Format::Glb) checked(io::animated_character(a).status, "character");
  return r.status;
}

// A 6 x 6 grid of vertices (50 triangles, one component with a boundary, every other row lifted):
// the mesh edit specs are evaluated on. Small, so that selections cost nothing.
struct EditGrid {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  EditRegion region;  // two handles, for parse_handle_transforms
  EditGrid() {
    const int n = 6;
    V.resize(n * n, 3);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) V.row(i * n + j) << 2.0 * j, i, (i % 2) * 0.25;
    F.resize(2 * (n - 1) * (n - 1), 3);
    int f = 0;
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j + 1 < n; ++j) {
        const int a = i * n + j, b = a + 1, c = a + n, d = c + 1;
        F.row(f++) << a, b, d;
        F.row(f++) << a, d, c;
      }
    region.handles = {{0, 1}, {34, 35}};
  }
};

// Edit specs (meshmorph edit --spec, the page's edit panel): parse_edit_spec on the grid, as
// run_edit_job calls it after loading the mesh. Text that is a JSON array goes to
// parse_handle_transforms (the page's drags) against the two-handle region instead.
inline Status read_edit_spec(const std::string& text) {
  static const EditGrid grid;
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '[') {
    const HandleTransformsResult t = parse_handle_transforms(text, grid.V, grid.region);
    if (checked(t.status, "handle transforms").ok() && t.transforms.size() != grid.region.handles.size())
      violated("handle transforms", "wrong count");
    return t.status;
  }
  const EditSpecResult r = parse_edit_spec(text, grid.V, grid.F);
  if (!checked(r.status, "edit spec").ok()) return r.status;
  const EditRegion& g = r.spec.region;
  if (g.handles.empty() || g.handles.size() != r.spec.transforms.size()) violated("edit spec", "handles");
  auto in_range = [&](const std::vector<int>& list) {
    for (int v : list)
      if (v < 0 || v >= grid.V.rows()) violated("edit spec", "vertex " + std::to_string(v) + " out of range");
  };
  in_range(g.roi);
  in_range(g.fixed);
  for (const auto& h : g.handles) in_range(h);
  return r.status;
}

// Landmark files (transfer --landmarks): io::parse_landmarks, which read_landmarks calls.
inline Status read_landmarks(const std::string& text) {
  std::vector<LandmarkPair> pairs;
  const Status s = io::parse_landmarks(text, "fuzz.json", &pairs);
  checked(s, "landmarks");
  if (!s.ok() && !pairs.empty()) violated("landmarks", "pairs left after an error");
  for (const LandmarkPair& p : pairs)
    if (p.reference < 0 || p.source < 0) violated("landmarks", "negative vertex");
  return s;
}

// Joint files and joint maps (retarget --target-joints / --joint-map, and the page): the same
// text through both readers; returns the first failure.
inline Status read_joints(const std::string& text) {
  const io::JointSetResult j = io::parse_joints_json(text);
  if (checked(j.status, "joints").ok() &&
      (j.joints.P.rows() != j.joints.size() || j.joints.P.cols() != 3 || !j.joints.P.allFinite()))
    violated("joints", "inconsistent joint set");
  const io::JointMapResult m = io::parse_joint_map_json(text);
  checked(m.status, "joint map");
  return j.status.ok() ? m.status : j.status;
}

// Merge specs (meshmorph merge --spec, the page's Merge panel saves them): parse_merge_spec, and
// what it accepts must read back unchanged from its own JSON (the page's save, the CLI's read).
inline Status read_merge_spec(const std::string& text) {
  const app::MergeSpecResult r = app::parse_merge_spec(text);
  if (!checked(r.status, "merge spec").ok()) return r.status;
  const std::string saved = app::merge_spec_json(r.spec);
  const app::MergeSpecResult again = app::parse_merge_spec(saved);
  if (!again.status.ok()) violated("merge spec", "its own JSON does not read back: " + again.status.message);
  if (app::merge_spec_json(again.spec) != saved) violated("merge spec", "the round trip changed the spec");
  return r.status;
}

// By harness name (gltf glb obj off ply edit_spec merge_spec landmarks joints): what tests/bad/<name>/ holds.
inline Status read_input(const std::string& harness, const std::vector<uint8_t>& bytes) {
  const std::string text(bytes.begin(), bytes.end());
  if (harness == "gltf") return read_mesh(io::Format::Gltf, bytes);
  if (harness == "glb") return read_mesh(io::Format::Glb, bytes);
  if (harness == "obj") return read_mesh(io::Format::Obj, bytes);
  if (harness == "off") return read_mesh(io::Format::Off, bytes);
  if (harness == "ply") return read_mesh(io::Format::Ply, bytes);
  if (harness == "edit_spec") return read_edit_spec(text);
  if (harness == "merge_spec") return read_merge_spec(text);
  if (harness == "landmarks") return read_landmarks(text);
  if (harness == "joints") return read_joints(text);
  violated("read_input", "unknown harness " + harness);
}

}  // namespace mm::fuzz
