#include "io/parts_file.h"

#include <cmath>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "io/asset.h"
#include "io/json_text.h"

namespace mm::io {

namespace {

bool parts_vec3(const nlohmann::json& j, Eigen::Vector3d* v) {
  if (!j.is_array() || j.size() != 3) return false;
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number()) return false;
    (*v)[k] = j[k].get<double>();
    if (!std::isfinite((*v)[k])) return false;
  }
  return true;
}

bool parts_index(const nlohmann::json& v, int* out) {
  if (v.is_number_unsigned()) {
    if (v.get<uint64_t>() > uint64_t{INT32_MAX}) return false;
  } else if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() > INT32_MAX) {
    return false;
  }
  *out = v.get<int>();
  return true;
}

Status parts_region(const nlohmann::json& j, const std::string& where, PartRegion* r) {
  auto bad = [&](const std::string& what) { return Status::error(StatusCode::ParseError, where + ": " + what); };
  if (!j.is_object()) return bad("expected an object with \"disk\", \"plane\" or \"vertices\"");
  if (j.contains("disk")) {
    const nlohmann::json& d = j["disk"];
    r->kind = PartRegionKind::Disk;
    if (!d.is_object() || !d.contains("seed") || !parts_index(d["seed"], &r->seed))
      return bad("disk needs \"seed\" (a vertex index)");
    if (!d.contains("radius") || !d["radius"].is_number() || !(d["radius"].get<double>() > 0) ||
        !std::isfinite(d["radius"].get<double>()))
      return bad("disk needs \"radius\" > 0 (fraction of the bounding-box diagonal)");
    r->radius = d["radius"].get<double>();
    return Status::success();
  }
  if (j.contains("plane")) {
    const nlohmann::json& p = j["plane"];
    r->kind = PartRegionKind::Plane;
    if (!p.is_object() || !p.contains("point") || !parts_vec3(p["point"], &r->point) || !p.contains("normal") ||
        !parts_vec3(p["normal"], &r->normal) || !p.contains("keep") || !parts_vec3(p["keep"], &r->keep))
      return bad("plane needs \"point\", \"normal\" and \"keep\" (three finite numbers each)");
    return Status::success();
  }
  if (j.contains("vertices")) {
    const nlohmann::json& v = j["vertices"];
    r->kind = PartRegionKind::Vertices;
    if (!v.is_array() || v.empty()) return bad("\"vertices\" must be a non-empty array of vertex indices");
    for (const auto& x : v) {
      int i = 0;
      if (!parts_index(x, &i)) return bad("\"vertices\" must hold non-negative integers");
      r->vertices.push_back(i);
    }
    return Status::success();
  }
  return bad("expected \"disk\", \"plane\" or \"vertices\"");
}

Status parts_list(const nlohmann::json& list, const std::string& where, std::vector<PartPair>* out) {
  if (!list.is_array()) return Status::error(StatusCode::ParseError, where + ": expected an array of parts");
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string at = where + "[" + std::to_string(i) + "]";
    const nlohmann::json& p = list[i];
    if (!p.is_object() || !p.contains("source"))
      return Status::error(StatusCode::ParseError, at + ": a part needs a \"source\" region");
    PartPair pp;
    if (p.contains("name") && p["name"].is_string()) pp.name = p["name"].get<std::string>();
    if (Status s = parts_region(p["source"], at + ".source", &pp.source); !s.ok()) return s;
    if (p.contains("reference")) {
      if (Status s = parts_region(p["reference"], at + ".reference", &pp.reference); !s.ok()) return s;
    } else {
      pp.reference = pp.source;
    }
    if (p.contains("children"))
      if (Status s = parts_list(p["children"], at + ".children", &pp.children); !s.ok()) return s;
    out->push_back(std::move(pp));
  }
  return Status::success();
}

nlohmann::json parts_region_json(const PartRegion& r) {
  nlohmann::json j = nlohmann::json::object();
  auto v3 = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  switch (r.kind) {
    case PartRegionKind::Disk: j["disk"] = {{"seed", r.seed}, {"radius", r.radius}}; break;
    case PartRegionKind::Plane:
      j["plane"] = {{"point", v3(r.point)}, {"normal", v3(r.normal)}, {"keep", v3(r.keep)}};
      break;
    case PartRegionKind::Vertices: j["vertices"] = r.vertices; break;
  }
  return j;
}

nlohmann::json parts_list_json(const std::vector<PartPair>& parts) {
  nlohmann::json list = nlohmann::json::array();
  for (const PartPair& p : parts) {
    nlohmann::json j = nlohmann::json::object();
    j["name"] = p.name;
    j["source"] = parts_region_json(p.source);
    j["reference"] = parts_region_json(p.reference);
    if (!p.children.empty()) j["children"] = parts_list_json(p.children);
    list.push_back(std::move(j));
  }
  return list;
}

}  // namespace

Status parse_parts(std::string_view text, const std::string& name, PartsSpec* spec) {
  *spec = {};
  if (Status d = check_json_depth(text, name); !d.ok()) return d;
  const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("parts"))
    return Status::error(StatusCode::ParseError, name + ": expected a JSON object with an array \"parts\"");
  Status s = parts_list(j["parts"], name + ": parts", &spec->parts);
  if (!s.ok()) *spec = {};
  return s;
}

Status read_parts(const std::string& path, PartsSpec* spec) {
  std::vector<uint8_t> bytes;
  if (Status s = read_file(path, &bytes); !s.ok()) return s;
  return parse_parts(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), path, spec);
}

std::string parts_json(const PartsSpec& spec, const std::string& comment) {
  nlohmann::json j = nlohmann::json::object();
  if (!comment.empty()) j["comment"] = comment;
  j["parts"] = parts_list_json(spec.parts);
  return j.dump(2) + "\n";
}

Status write_parts(const std::string& path, const PartsSpec& spec, const std::string& comment) {
  const std::string text = parts_json(spec, comment);
  return write_file_atomic(path, std::vector<uint8_t>(text.begin(), text.end()));
}

}  // namespace mm::io
