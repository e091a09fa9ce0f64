#include "test_support.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/asset.h"

namespace mm::test {

namespace {
bool g_update_golden = false;
}

void set_update_golden(bool on) { g_update_golden = on; }
bool update_golden() { return g_update_golden; }

std::string data_path(const std::string& relative) {
  return std::string(MM_SOURCE_DIR) + "/data/" + relative;
}

std::string tests_path(const std::string& relative) {
  return std::string(MM_SOURCE_DIR) + "/tests/" + relative;
}

std::string scratch_path(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::current_path() / "test-scratch";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

Mesh load_mesh(const std::string& relative) {
  const io::LoadResult r = io::load_asset(data_path(relative));
  EXPECT_TRUE(r.status.ok()) << relative << ": " << r.status.message;
  return r.asset.mesh();
}

void expect_golden(const std::string& name, const Eigen::MatrixXd& values, double tolerance) {
  const std::string path = tests_path("golden/" + name + ".json");
  if (g_update_golden) {
    nlohmann::json j;
    j["tolerance"] = tolerance;
    j["rows"] = values.rows();
    j["cols"] = values.cols();
    std::vector<double> data;
    for (int r = 0; r < values.rows(); ++r)
      for (int c = 0; c < values.cols(); ++c) data.push_back(values(r, c));
    j["data"] = data;
    std::ofstream(path) << j.dump(1) << "\n";
    return;
  }
  std::ifstream in(path);
  ASSERT_TRUE(in.good()) << "missing golden file " << path << " (run with --update-golden)";
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << "golden file " << path << " is not valid JSON";
  const double tol = j.value("tolerance", tolerance);
  ASSERT_EQ(j["rows"].get<long>(), values.rows()) << name;
  ASSERT_EQ(j["cols"].get<long>(), values.cols()) << name;
  const auto data = j["data"].get<std::vector<double>>();
  double worst = 0;
  long worst_at = -1;
  for (int r = 0; r < values.rows(); ++r)
    for (int c = 0; c < values.cols(); ++c) {
      const double d = std::abs(values(r, c) - data[r * values.cols() + c]);
      if (!(d <= worst)) {
        worst = d;
        worst_at = r * values.cols() + c;
      }
    }
  EXPECT_LE(worst, tol) << "golden " << name << ": largest difference " << worst << " at flat index "
                        << worst_at << " (tolerance " << tol << ")";
}

std::string data_uri(const std::vector<uint8_t>& data) {
  static const char* a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out = "data:application/octet-stream;base64,";
  for (size_t i = 0; i < data.size(); i += 3) {
    const unsigned t = (unsigned(data[i]) << 16) | (i + 1 < data.size() ? unsigned(data[i + 1]) << 8 : 0) |
                       (i + 2 < data.size() ? unsigned(data[i + 2]) : 0);
    out += a[(t >> 18) & 63];
    out += a[(t >> 12) & 63];
    out += i + 1 < data.size() ? a[(t >> 6) & 63] : '=';
    out += i + 2 < data.size() ? a[t & 63] : '=';
  }
  return out;
}

Progress ForwardProgress::sink() {
  return Progress([this](const std::string& stage, double f) {
    const std::string previous = stages.empty() ? "" : stages.back();
    if (f < last - 1e-12) backwards.push_back(previous + " at " + std::to_string(last) + " -> " + stage + " at " + std::to_string(f));
    if (stages.empty() || stages.back() != stage) stages.push_back(stage);
    last = f;
    ++reports;
    return true;
  });
}

}  // namespace mm::test
