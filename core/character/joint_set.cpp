#include "character/joint_set.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace mm {

namespace joint_set_detail {

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

}  // namespace joint_set_detail

int JointSet::find(const std::string& name) const {
  for (int i = 0; i < size(); ++i)
    if (names[i] == name) return i;
  return -1;
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
                                   joint_set_detail::joined_names(source.names) + ")");
      return r;
    }
    if (t < 0) {
      r.status = Status::error(StatusCode::InvalidArgument,
                               "joint map names target joint '" + tname + "', which the target does not have (target joints: " +
                                   joint_set_detail::joined_names(target.names) + ")");
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
    const std::string ns = joint_set_detail::normalized_joint_name(source.names[s]);
    for (int t = 0; t < target.size(); ++t)
      if (source_of[t] < 0 && joint_set_detail::normalized_joint_name(target.names[t]) == ns) {
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
                                   joint_set_detail::joined_names(unmatched) +
                                   " match no source joint; use the source's joint names (" +
                                   joint_set_detail::joined_names(source.names) + ") or a joint map");
      return r;
    }
    r.warnings.push_back(std::to_string(unmatched.size()) + " target joints have no source joint: " +
                         joint_set_detail::joined_names(unmatched));
  }
  for (int s = 0; s < source.size(); ++s)
    if (target_of[s] >= 0) r.pairs.push_back({s, target_of[s]});
  if (static_cast<int>(r.pairs.size()) < min_pairs) {
    r.status = Status::error(StatusCode::InvalidArgument,
                             "only " + std::to_string(r.pairs.size()) + " source joints match target joints (need " +
                                 std::to_string(min_pairs) + "); source joints: " +
                                 joint_set_detail::joined_names(source.names) +
                                 "; target joints: " + joint_set_detail::joined_names(target.names));
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
