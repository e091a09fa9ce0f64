#include "retarget/joint_set.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <nlohmann/json.hpp>

namespace mm {

namespace retarget_detail {

std::string normalized_joint_name(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == ' ' || c == '_' || c == '-' || c == '.' || c == ':') continue;
    out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  return out;
}

std::string joined_names(const std::vector<std::string>& names, size_t limit = 12) {
  std::string s;
  for (size_t i = 0; i < names.size() && i < limit; ++i) s += (i ? ", " : "") + names[i];
  if (names.size() > limit) s += ", ... (" + std::to_string(names.size()) + " in all)";
  return s;
}

}  // namespace retarget_detail

int JointSet::find(const std::string& name) const {
  for (int i = 0; i < size(); ++i)
    if (names[i] == name) return i;
  return -1;
}

JointSetResult parse_joints_json(const std::string& text) {
  JointSetResult r;
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
                               "joint '" + it.key() + "' must be an array of 3 finite numbers");
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
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    r.status = Status::error(StatusCode::ParseError,
                             "joint map must be a JSON object {\"source joint\": \"target joint\", ...}");
    return r;
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!it.value().is_string()) {
      r.status = Status::error(StatusCode::ParseError, "joint map entry '" + it.key() + "' must be a string");
      return r;
    }
    r.source_to_target[it.key()] = it.value().get<std::string>();
  }
  return r;
}

JointMatchResult match_joints(const JointSet& source, const JointSet& target,
                              const std::map<std::string, std::string>& source_to_target, int min_pairs) {
  JointMatchResult r;
  std::vector<int> target_of(source.size(), -1), source_of(target.size(), -1);
  auto link = [&](int s, int t) {
    target_of[s] = t;
    source_of[t] = s;
  };
  for (const auto& [sname, tname] : source_to_target) {  // std::map: deterministic order
    const int s = source.find(sname), t = target.find(tname);
    if (s < 0) {
      r.status = Status::error(StatusCode::InvalidArgument,
                               "joint map names source joint '" + sname + "', which the source does not have (source joints: " +
                                   retarget_detail::joined_names(source.names) + ")");
      return r;
    }
    if (t < 0) {
      r.status = Status::error(StatusCode::InvalidArgument,
                               "joint map names target joint '" + tname + "', which the target does not have (target joints: " +
                                   retarget_detail::joined_names(target.names) + ")");
      return r;
    }
    if (target_of[s] >= 0 || source_of[t] >= 0) {
      r.status = Status::error(StatusCode::InvalidArgument,
                               "joint map uses joint '" + sname + "' or '" + tname + "' twice");
      return r;
    }
    link(s, t);
  }
  for (int s = 0; s < source.size(); ++s) {
    if (target_of[s] >= 0) continue;
    const int t = target.find(source.names[s]);
    if (t >= 0 && source_of[t] < 0) link(s, t);
  }
  for (int s = 0; s < source.size(); ++s) {
    if (target_of[s] >= 0) continue;
    const std::string ns = retarget_detail::normalized_joint_name(source.names[s]);
    for (int t = 0; t < target.size(); ++t)
      if (source_of[t] < 0 && retarget_detail::normalized_joint_name(target.names[t]) == ns) {
        link(s, t);
        break;
      }
  }
  std::vector<std::string> unmatched;
  for (int t = 0; t < target.size(); ++t)
    if (source_of[t] < 0) unmatched.push_back(target.names[t]);
  if (!unmatched.empty()) {
    if (target.from_user) {
      r.status = Status::error(StatusCode::InvalidArgument,
                               "target joint" + std::string(unmatched.size() > 1 ? "s " : " ") +
                                   retarget_detail::joined_names(unmatched) +
                                   " match no source joint; use the source's joint names (" +
                                   retarget_detail::joined_names(source.names) + ") or a joint map");
      return r;
    }
    r.warnings.push_back(std::to_string(unmatched.size()) + " target joints have no source joint: " +
                         retarget_detail::joined_names(unmatched));
  }
  for (int s = 0; s < source.size(); ++s)
    if (target_of[s] >= 0) r.pairs.push_back({s, target_of[s]});
  if (static_cast<int>(r.pairs.size()) < min_pairs) {
    r.status = Status::error(StatusCode::InvalidArgument,
                             "only " + std::to_string(r.pairs.size()) + " source joints match target joints (need " +
                                 std::to_string(min_pairs) + "); source joints: " +
                                 retarget_detail::joined_names(source.names) +
                                 "; target joints: " + retarget_detail::joined_names(target.names));
    return r;
  }
  return r;
}

std::vector<int> joint_depths(const JointSet& joints) {
  std::vector<int> depth(joints.size(), 0);
  if (static_cast<int>(joints.parent.size()) != joints.size()) return depth;
  for (int j = 0; j < joints.size(); ++j) {
    int d = 0;
    for (int p = joints.parent[j]; p >= 0 && d <= joints.size(); p = joints.parent[p]) ++d;
    depth[j] = d;
  }
  return depth;
}

}  // namespace mm
