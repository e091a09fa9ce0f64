#include "io/info_report.h"

#include <sstream>

#include <nlohmann/json.hpp>

namespace mm::io {

namespace {

nlohmann::json mesh_report_json(const MeshReport& r) {
  nlohmann::json j;
  j["vertices"] = r.num_vertices;
  j["faces"] = r.num_faces;
  j["edges"] = r.num_edges;
  j["bbox_min"] = {r.bbox_min.x(), r.bbox_min.y(), r.bbox_min.z()};
  j["bbox_max"] = {r.bbox_max.x(), r.bbox_max.y(), r.bbox_max.z()};
  j["bbox_diagonal"] = r.bbox_diagonal;
  j["components"] = r.num_components;
  j["component_faces"] = r.component_sizes;
  nlohmann::json loops = nlohmann::json::array();
  for (const auto& l : r.boundary_loops) loops.push_back({{"length", l.size()}, {"first_vertex", l.front()}});
  j["boundary_loops"] = loops;
  j["euler_characteristic"] = r.euler_characteristic;
  j["closed"] = r.closed();
  nlohmann::json defects = nlohmann::json::array();
  for (const auto& d : r.defects)
    defects.push_back({{"defect", mesh_defect_name(d.defect)}, {"count", d.count}, {"example", d.example}});
  j["defects"] = defects;
  return j;
}

}  // namespace

InfoReport info_report(const Asset& asset) {
  InfoReport out;
  out.welded = validate_mesh(asset.weld.V, asset.weld.F);
  // The raw layout is validated again only where welding changed it (glTF seams, duplicates).
  const bool same = asset.V_raw.rows() == asset.weld.V.rows() && asset.F_raw.rows() == asset.weld.F.rows() &&
                    asset.V_raw.cols() == asset.weld.V.cols() && asset.F_raw.cols() == asset.weld.F.cols() &&
                    asset.F_raw == asset.weld.F && asset.V_raw == asset.weld.V;
  out.raw = same ? out.welded : validate_mesh(asset.V_raw, asset.F_raw);

  nlohmann::json j;
  j["file"] = asset.source_name;
  j["format"] = format_name(asset.format);
  j["raw_vertices"] = asset.V_raw.rows();
  j["raw_faces"] = asset.F_raw.rows();
  nlohmann::json prims = nlohmann::json::array();
  for (const auto& p : asset.primitives)
    prims.push_back({{"name", p.name}, {"vertices", p.num_vertices}, {"faces", p.num_faces}, {"skinned", p.skinned},
                     {"rest_pose_from_skin", p.rest_skin.rows() > 0}});
  j["primitives"] = prims;
  j["welded"] = mesh_report_json(out.welded);
  j["raw_defects"] = mesh_report_json(out.raw)["defects"];
  j["warnings"] = asset.warnings;
  out.json = j.dump();

  std::ostringstream os;
  os << "file: " << asset.source_name << " (" << format_name(asset.format) << ")\n"
     << "raw layout: " << asset.V_raw.rows() << " vertices, " << asset.F_raw.rows() << " triangles in "
     << asset.primitives.size() << " primitive(s)\n";
  for (const auto& p : asset.primitives)
    os << "  " << (p.name.empty() ? "(unnamed)" : p.name) << ": " << p.num_vertices << " vertices, " << p.num_faces
       << " triangles" << (p.skinned ? ", skinned" : "")
       << (p.rest_skin.rows() > 0 ? " (shown in its rest pose: its bind pose differs)" : "") << "\n";
  os << "welded mesh (what the methods use):\n";
  std::istringstream body(out.welded.to_text());
  for (std::string line; std::getline(body, line);) os << "  " << line << "\n";
  for (const auto& w : asset.warnings) os << "warning: " << w << "\n";
  out.text = os.str();
  return out;
}

}  // namespace mm::io
