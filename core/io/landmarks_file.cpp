#include "io/landmarks_file.h"

#include <cstdint>

#include <nlohmann/json.hpp>

#include "io/asset.h"
#include "io/json_text.h"

namespace mm::io {

Status parse_landmarks(std::string_view text, const std::string& name, std::vector<LandmarkPair>* pairs) {
  pairs->clear();
  if (Status d = check_json_depth(text, name); !d.ok()) return d;
  const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("pairs") || !j["pairs"].is_array())
    return Status::error(StatusCode::ParseError, name + ": expected a JSON object with an array \"pairs\"");
  const nlohmann::json& list = j["pairs"];
  auto vertex = [](const nlohmann::json& v) {
    // A huge unsigned value is number_unsigned, and get<int64_t> of it would wrap: test both kinds.
    if (v.is_number_unsigned()) return v.get<uint64_t>() <= uint64_t{INT32_MAX};
    return v.is_number_integer() && v.get<int64_t>() >= 0 && v.get<int64_t>() <= INT32_MAX;
  };
  for (size_t i = 0; i < list.size(); ++i) {
    const nlohmann::json& p = list[i];
    if (!p.is_array() || p.size() != 2 || !vertex(p[0]) || !vertex(p[1])) {
      pairs->clear();
      return Status::error(StatusCode::ParseError, name + ": pair " + std::to_string(i) +
                                                       " is not [reference vertex, source vertex] (two non-negative integers)");
    }
    pairs->push_back({p[0].get<int>(), p[1].get<int>()});
  }
  return Status::success();
}

Status read_landmarks(const std::string& path, std::vector<LandmarkPair>* pairs) {
  std::vector<uint8_t> bytes;
  Status s = read_file(path, &bytes);
  if (!s.ok()) return s;
  return parse_landmarks(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), path, pairs);
}

}  // namespace mm::io
