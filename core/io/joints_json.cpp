#include "io/joints_json.h"

#include "io/json_text.h"

#include <cmath>

#include <nlohmann/json.hpp>

namespace mm::io {

JointSetResult parse_joints_json(const std::string& text) {
  JointSetResult r;
  if (Status d = check_json_depth(text, "joints file"); !d.ok()) return {d, {}};
  // Parsed without exceptions (the wasm build may have them off): discarded value on error.
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    r.status = Status::error(StatusCode::ParseError,
                             "joints file must be a JSON object {\"joint name\": [x, y, z], ...}");
    return r;
  }
  if (j.empty()) {
    r.status = Status::error(StatusCode::ParseError, "joints file has no joints");
    return r;
  }
  r.joints.P.resize(static_cast<int>(j.size()), 3);
  int i = 0;
  for (auto it = j.begin(); it != j.end(); ++it, ++i) {  // nlohmann orders keys: deterministic
    const auto& v = it.value();
    bool ok = v.is_array() && v.size() == 3;
    for (size_t k = 0; ok && k < 3; ++k) ok = v[k].is_number() && std::isfinite(v[k].get<double>());
    if (!ok) {
      r.status = Status::error(StatusCode::ParseError,
                               "joint '" + quote_input(it.key(), 60) + "' must be an array of 3 finite numbers");
      return r;
    }
    r.joints.names.push_back(it.key());
    for (int k = 0; k < 3; ++k) r.joints.P(i, k) = v[k].get<double>();
  }
  r.joints.from_user = true;
  return r;
}

JointMapResult parse_joint_map_json(const std::string& text) {
  JointMapResult r;
  if (Status d = check_json_depth(text, "joint map"); !d.ok()) return {d, {}};
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    r.status = Status::error(StatusCode::ParseError,
                             "joint map must be a JSON object {\"source joint\": \"target joint\", ...}");
    return r;
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!it.value().is_string()) {
      r.status = Status::error(StatusCode::ParseError, "joint map entry '" + quote_input(it.key(), 60) + "' must be a string");
      return r;
    }
    r.source_to_target[it.key()] = it.value().get<std::string>();
  }
  return r;
}

}  // namespace mm::io
