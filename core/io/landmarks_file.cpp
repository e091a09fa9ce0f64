#include "io/landmarks_file.h"

#include <cstdint>

#include <nlohmann/json.hpp>

#include "io/asset.h"
#include "io/json_text.h"

namespace mm::io {

Status read_landmarks(const std::string& path, std::vector<LandmarkPair>* pairs) {
  std::vector<uint8_t> bytes;
  Status s = read_file(path, &bytes);
  if (!s.ok()) return s;
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (Status d = check_json_depth(text, path); !d.ok()) return d;
  nlohmann::json j = nlohmann::json::parse(bytes.begin(), bytes.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("pairs") || !j["pairs"].is_array())
    return Status::error(StatusCode::ParseError, path + ": expected a JSON object with an array \"pairs\"");
  for (size_t i = 0; i < j["pairs"].size(); ++i) {
    const auto& p = j["pairs"][i];
    auto vertex = [](const nlohmann::json& v) {
      return v.is_number_integer() && v.get<int64_t>() >= 0 && v.get<int64_t>() <= INT32_MAX;
    };
    if (!p.is_array() || p.size() != 2 || !vertex(p[0]) || !vertex(p[1]))
      return Status::error(StatusCode::ParseError, path + ": pair " + std::to_string(i) +
                                                       " is not [reference vertex, source vertex] (two non-negative integers)");
    pairs->push_back({p[0].get<int>(), p[1].get<int>()});
  }
  return Status::success();
}

}  // namespace mm::io
