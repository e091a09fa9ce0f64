#include "app/merge_job.h"

#include <chrono>
#include <cstdio>
#include <set>

#include <nlohmann/json.hpp>

#include "app/edit_job.h"
#include "app/json_options.h"
#include "io/asset.h"
#include "io/json_text.h"
#include "mesh/topology.h"

namespace mm::app {

const OptionSchema<MergeOptions>& merge_options() {
  using O = MergeOptions;
  static const OptionSchema<O> schema = [] {
    OptionSchema<O> s("merge", "attach a source mesh to a target along boundary loops (paper 001 Sec. 5)");
    s.choice<MergeMode>("mode", [](O& o) -> MergeMode& { return o.mode; },
                        {{"independent", MergeMode::ConfigurationIndependent},
                         {"dependent", MergeMode::ConfigurationDependent}},
                        "independent: the source may sit anywhere (Sec. 5.1); dependent: keep its placement, "
                        "deform a band near the seam (Sec. 5.2)");
    s.number("gradient_weight", [](O& o) -> double& { return o.gradient_weight; }, 1e-12, kUnbounded,
             "weight of the boundary deformation-gradient constraints M_c = R S (Eq. 7)");
    s.number("refine_ratio", [](O& o) -> double& { return o.refine_ratio; }, 0, kUnbounded,
             "refine a source loop with this many times fewer vertices than its target loop (Sec. 6; 0 = off)");
    s.number("roi_width", [](O& o) -> double& { return o.roi_width; }, 1e-12, kUnbounded,
             "dependent mode: deformed band width from the seam, × the source's bounding-box diagonal");
    s.integer("smoothing_iterations", [](O& o) -> int& { return o.smoothing_iterations; }, 0, 1000,
              "umbrella-operator iterations near the seam after zipping");
    s.integer("smoothing_rings", [](O& o) -> int& { return o.smoothing_rings; }, 0, 20,
              "vertices within this many edges of the seam are smoothed");
    s.number("smoothing_step", [](O& o) -> double& { return o.smoothing_step; }, 0, 1,
             "step of each umbrella iteration");
    s.number("transition_target_width", [](O& o) -> double& { return o.transition_target_width; }, 0, kUnbounded,
             "transition region on the target side of the seam (Sec. 5.3), × target diagonal; 0 = off");
    s.number("transition_source_width", [](O& o) -> double& { return o.transition_source_width; }, 0, kUnbounded,
             "transition region on the source side of the seam (Sec. 5.3), × target diagonal; 0 = off");
    s.boolean("zip", [](O& o) -> bool& { return o.zip; },
              "join the meshes into one watertight mesh (false: deformed source beside the target)");
    add_editor_options<O>(s, [](O& o) -> LaplacianEditOptions& { return o.editor; });
    return s;
  }();
  return schema;
}

namespace {

using Json = nlohmann::json;

bool read_indices(const Json& j, const std::string& where, std::vector<int>* out, Status* st) {
  if (!j.is_array()) {
    *st = Status::error(StatusCode::ParseError, "merge spec: " + where + " must be an array of vertex indices");
    return false;
  }
  for (const Json& v : j) {
    if (!v.is_number_integer()) {
      *st = Status::error(StatusCode::ParseError, "merge spec: " + where + " must hold integer vertex indices");
      return false;
    }
    const long long x = v.get<long long>();
    if (x < 0 || x > 2000000000) {
      *st = Status::error(StatusCode::InvalidArgument, "merge spec: " + where + " has a negative or huge index");
      return false;
    }
    out->push_back(static_cast<int>(x));
  }
  return true;
}

bool check_keys(const Json& obj, const std::set<std::string>& allowed, const std::string& where, Status* st) {
  for (auto it = obj.begin(); it != obj.end(); ++it)
    if (!allowed.count(it.key())) {
      *st = Status::error(StatusCode::ParseError,
                          "merge spec: unknown key \"" + io::quote_input(it.key(), 60) + "\" in " + where);
      return false;
    }
  return true;
}

}  // namespace

MergeSpecResult parse_merge_spec(const std::string& text) {
  MergeSpecResult out;
  if (Status d = io::check_json_depth(text, "merge spec"); !d.ok()) {
    out.status = d;
    return out;
  }
  const Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    out.status = Status::error(StatusCode::ParseError, "merge spec is not valid JSON");
    return out;
  }
  Status& st = out.status;
  try {
    if (!j.is_object()) {
      st = Status::error(StatusCode::ParseError, "merge spec must be a JSON object");
      return out;
    }
    if (!check_keys(j, {"pairs", "fixed", "options", "comment"}, "the merge spec", &st)) return out;
    if (!j.contains("pairs") || !j["pairs"].is_array() || j["pairs"].empty()) {
      st = Status::error(StatusCode::ParseError, "merge spec: \"pairs\" must be a non-empty array of boundary pairs");
      return out;
    }
    for (size_t i = 0; i < j["pairs"].size(); ++i) {
      const Json& p = j["pairs"][i];
      const std::string where = "pairs[" + std::to_string(i) + "]";
      if (!p.is_object()) {
        st = Status::error(StatusCode::ParseError, "merge spec: " + where + " must be an object");
        return out;
      }
      if (!check_keys(p, {"target_keys", "source_keys", "target_loop", "source_loop"}, where, &st)) return out;
      MergeBoundaryPair bp;
      if (!p.contains("target_keys") || !p.contains("source_keys")) {
        st = Status::error(StatusCode::ParseError, "merge spec: " + where + " needs target_keys and source_keys");
        return out;
      }
      if (!read_indices(p["target_keys"], where + ".target_keys", &bp.target_keys, &st) ||
          !read_indices(p["source_keys"], where + ".source_keys", &bp.source_keys, &st))
        return out;
      for (const char* name : {"target_loop", "source_loop"}) {
        if (!p.contains(name)) continue;
        if (!p[name].is_number_integer() || p[name].get<long long>() < 0 || p[name].get<long long>() > 1000000) {
          st = Status::error(StatusCode::ParseError, "merge spec: " + where + "." + name + " must be a loop index ≥ 0");
          return out;
        }
        (std::string(name) == "target_loop" ? bp.target_loop : bp.source_loop) = p[name].get<int>();
      }
      out.spec.pairs.push_back(bp);
    }
    if (j.contains("fixed") && !read_indices(j["fixed"], "fixed", &out.spec.fixed, &st)) return out;
    if (j.contains("options"))
      st = set_options_from_json(j["options"], merge_options(), &out.spec.options, "merge spec");
  } catch (const std::exception& e) {
    st = Status::error(StatusCode::ParseError, io::cap_message(std::string("merge spec: ") + e.what()));
  }
  return out;
}

std::string merge_spec_json(const MergeSpec& spec) {
  Json j;
  j["pairs"] = Json::array();
  for (const MergeBoundaryPair& p : spec.pairs) {
    Json q;
    q["target_keys"] = p.target_keys;
    q["source_keys"] = p.source_keys;
    if (p.target_loop >= 0) q["target_loop"] = p.target_loop;
    if (p.source_loop >= 0) q["source_loop"] = p.source_loop;
    j["pairs"].push_back(q);
  }
  if (!spec.fixed.empty()) j["fixed"] = spec.fixed;
  j["options"]["mode"] = spec.options.mode == MergeMode::ConfigurationDependent ? "dependent" : "independent";
  return j.dump(2);
}

MergeResult merge_assets(const io::Asset& target, const io::Asset& source, const MergeSpec& spec,
                         const Progress& progress) {
  MergeInput in;
  in.target_V = target.weld.V;
  in.target_F = target.weld.F;
  in.source_V = source.weld.V;
  in.source_F = source.weld.F;
  in.pairs = spec.pairs;
  in.source_fixed = spec.fixed;
  return merge_meshes(in, spec.options, progress);
}

MergeJobResult run_merge_job(const MergeJobRequest& request, const Progress& progress) {
  MergeJobResult r;
  const MergeJobFiles& f = request.files;
  const auto t0 = std::chrono::steady_clock::now();
  if (!(r.status = io::check_output_path(f.out)).ok()) return r;
  std::vector<uint8_t> spec_bytes;
  if (!(r.status = io::read_file(f.spec, &spec_bytes)).ok()) return r;
  MergeSpecResult sr = parse_merge_spec(std::string(spec_bytes.begin(), spec_bytes.end()));
  if (!sr.status.ok()) {
    r.status = Status::error(sr.status.code, f.spec + ": " + sr.status.message);
    return r;
  }
  if (request.set_overrides && !(r.status = request.set_overrides(sr.spec.options)).ok()) return r;
  const io::LoadResult target = io::load_asset(f.target);
  if (!(r.status = target.status).ok()) return r;
  const io::LoadResult source = io::load_asset(f.source);
  if (!(r.status = source.status).ok()) return r;
  const MergeResult m = merge_assets(target.asset, source.asset, sr.spec, progress);
  if (!(r.status = m.status).ok()) return r;
  if (!(r.status = io::save_asset_with_mesh(target.asset, m.V, m.F, f.out)).ok()) return r;
  r.stats = m.stats;
  r.vertices = static_cast<int>(m.V.rows());
  r.faces = static_cast<int>(m.F.rows());
  r.boundary_loops = static_cast<int>(boundary_loops(m.F, r.vertices).size());
  for (const EdgeUse& e : edge_uses(m.F)) r.nonmanifold_edges += e.faces > 2;
  r.total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::string merge_summary(const MergeJobResult& r, const std::string& out_path) {
  const MergeStats& s = r.stats;
  std::string text;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "merge: target %d + source %d vertices (%d added by boundary refinement), %d boundary constraints\n"
                "  precompute %.0f ms (factor %.0f ms), solve %.0f ms, zip %.0f ms; total %.0f ms\n"
                "  result: %d vertices, %d faces, %d boundary loop(s), %d non-manifold edge(s)\n",
                s.target_vertices, s.source_vertices - s.refined_vertices, s.refined_vertices, s.boundary_constraints,
                s.precompute_ms, s.editor.factor_ms, s.solve_ms, s.zip_ms, r.total_ms, r.vertices, r.faces,
                r.boundary_loops, r.nonmanifold_edges);
  text += buf;
  for (size_t i = 0; i < s.seams.size(); ++i) {
    const MergeSeamReport& z = s.seams[i];
    std::snprintf(buf, sizeof buf,
                  "  seam %zu: %d band faces removed, %d zip faces (min angle %.1f°, %d flipped), "
                  "dihedral angle max %.1f° mean %.1f°\n",
                  i, z.removed_faces, z.zip_faces, z.min_angle_deg, z.flipped_faces, z.dihedral_max_deg,
                  z.dihedral_mean_deg);
    text += buf;
  }
  return text + "  wrote " + out_path + "\n";
}

CutResult cut_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const CutJobRequest& req) {
  if (req.plane) return cut_plane(V, F, req.point, req.normal, req.has_keep ? req.keep : Eigen::Vector3d(req.point + req.normal));
  return cut_disk(V, F, req.disk_vertex, req.disk_radius);
}

CutJobResult run_cut_job(const CutJobRequest& req) {
  CutJobResult r;
  if (!(r.status = io::check_output_path(req.out)).ok()) return r;
  const io::LoadResult lr = io::load_asset(req.in);
  if (!(r.status = lr.status).ok()) return r;
  const CutResult c = cut_mesh(lr.asset.weld.V, lr.asset.weld.F, req);
  if (!(r.status = c.status).ok()) return r;
  if (!(r.status = io::save_asset_with_mesh(lr.asset, c.V, c.F, req.out)).ok()) return r;
  r.vertices = static_cast<int>(c.V.rows());
  r.faces = static_cast<int>(c.F.rows());
  r.boundary_loops = c.boundary_loops;
  return r;
}

}  // namespace mm::app
