#include "io/landmarks_file.h"

#include <nlohmann/json.hpp>

#include "io/asset.h"

namespace mm::io {

Status read_landmarks(const std::string& path, std::vector<LandmarkPair>* pairs) {
  std::vector<uint8_t> bytes;
  Status s = read_file(path, &bytes);
  if (!s.ok()) return s;
  nlohmann::json j = nlohmann::json::parse(bytes.begin(), bytes.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("pairs") || !j["pairs"].is_array())
    return Status::error(StatusCode::ParseError, path + ": expected a JSON object with an array \"pairs\"");
  for (size_t i = 0; i < j["pairs"].size(); ++i) {
    const auto& p = j["pairs"][i];
    if (!p.is_array() || p.size() != 2 || !p[0].is_number_integer() || !p[1].is_number_integer())
      return Status::error(StatusCode::ParseError, path + ": pair " + std::to_string(i) + " is not [int, int]");
    pairs->push_back({p[0].get<int>(), p[1].get<int>()});
  }
  return Status::success();
}

}  // namespace mm::io
