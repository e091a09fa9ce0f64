// Hostile and malformed inputs (issue 13): each class gets its own clear error — never a crash, an
// out-of-bounds read, a megabyte-long message or silently wrong geometry — and valid but less
// common glTF (triangle strips and fans) loads as triangles.
#include <gtest/gtest.h>

#include <cstring>

#include <nlohmann/json.hpp>

#include "io/asset.h"
#include "io/gltf_animation.h"
#include "io/joints_json.h"
#include "io/json_text.h"
#include "test_support.h"

#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

namespace mm {
namespace {

using io::Format;

std::vector<uint8_t> hostile_bytes(const std::string& s) { return {s.begin(), s.end()}; }

// A glTF whose buffer holds `floats` then `indices` (uint16); `patch` is merged into the JSON.
nlohmann::json hostile_gltf(const std::vector<float>& floats, const std::vector<uint16_t>& indices,
                            const nlohmann::json& patch = nlohmann::json::object()) {
  std::vector<uint8_t> b(floats.size() * 4 + indices.size() * 2);
  std::memcpy(b.data(), floats.data(), floats.size() * 4);
  if (!indices.empty()) std::memcpy(b.data() + floats.size() * 4, indices.data(), indices.size() * 2);
  nlohmann::json prim = {{"attributes", {{"POSITION", 0}}}};
  if (!indices.empty()) prim["indices"] = 1;
  nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes", {{{"primitives", {prim}}}}},
      {"buffers", {{{"byteLength", b.size()}, {"uri", test::data_uri(b)}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", floats.size() * 4}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", floats.size() / 3}, {"type", "VEC3"}}}}};
  if (!indices.empty()) {
    j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", floats.size() * 4}, {"byteLength", indices.size() * 2}});
    j["accessors"].push_back({{"bufferView", 1}, {"componentType", 5123}, {"count", indices.size()}, {"type", "SCALAR"}});
  }
  j.merge_patch(patch);
  return j;
}

io::LoadResult hostile_load(const nlohmann::json& j, const std::string& name = "hostile.gltf") {
  return io::load_asset_from_memory(hostile_bytes(j.dump()), Format::Gltf, name);
}

const std::vector<float> kQuad = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0};

TEST(Hostile, DeeplyNestedJsonIsRefusedBeforeAnyWalk) {
  // A million levels inside `extras`: tinygltf's recursive walk would overflow the stack.
  std::string text = hostile_gltf(kQuad, {0, 1, 2}).dump();
  const std::string deep = std::string(1000000, '[') + std::string(1000000, ']');
  text.insert(text.size() - 1, ",\"extras\":" + deep);
  const io::LoadResult r = io::load_asset_from_memory(hostile_bytes(text), Format::Gltf, "deep.gltf");
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("nested deeper than 256"), std::string::npos) << r.status.message;
  // Brackets inside strings do not count; escaped quotes do not end a string.
  EXPECT_TRUE(io::check_json_depth("{\"a\": \"[[[[\\\"[[[[\"}", "x", 2).ok());
  EXPECT_FALSE(io::check_json_depth("[[[1]]]", "x", 2).ok());
  // Every JSON reader applies it.
  EXPECT_EQ(io::parse_joints_json(deep).status.code, StatusCode::ParseError);
  EXPECT_EQ(io::parse_joint_map_json(deep).status.code, StatusCode::ParseError);
}

TEST(Hostile, OffsetsThatWrapAroundAreRefused) {
  const uint64_t near_max = 18446744073709551600ull;
  for (const char* key : {"byteOffset", "byteLength"}) {
    nlohmann::json j = hostile_gltf(kQuad, {0, 1, 2});
    j["bufferViews"][0][key] = near_max;
    const io::LoadResult r = hostile_load(j);
    EXPECT_EQ(r.status.code, StatusCode::ParseError) << key;
    EXPECT_NE(r.status.message.find("bufferView 0"), std::string::npos) << r.status.message.substr(0, 300);
  }
  // An accessor offset near 2^64 (offset + count·stride wraps to a small number).
  nlohmann::json a = hostile_gltf(kQuad, {0, 1, 2});
  a["accessors"][0]["byteOffset"] = near_max;
  io::LoadResult r = hostile_load(a);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  // Negative offsets are not "0".
  a = hostile_gltf(kQuad, {0, 1, 2});
  a["bufferViews"][0]["byteOffset"] = -12;
  r = hostile_load(a);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("non-negative"), std::string::npos) << r.status.message;
  a = hostile_gltf(kQuad, {0, 1, 2});
  a["accessors"][0]["byteOffset"] = -4;
  EXPECT_EQ(hostile_load(a).status.code, StatusCode::ParseError);
  a = hostile_gltf(kQuad, {0, 1, 2});
  a["accessors"][0]["count"] = -1;
  EXPECT_EQ(hostile_load(a).status.code, StatusCode::ParseError);
}

TEST(Hostile, ErrorMessagesDoNotEchoMegabytes) {
  // An 8 MiB unterminated string.
  std::string text = "{\"asset\": {\"version\": \"2.0\"}, \"x\": \"" + std::string(8 << 20, 'a');
  io::LoadResult r = io::load_asset_from_memory(hostile_bytes(text), Format::Gltf, "long.gltf");
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_LT(r.status.message.size(), 600u) << r.status.message.substr(0, 200);
  // A 1 MiB URI.
  nlohmann::json j = hostile_gltf(kQuad, {0, 1, 2});
  j["buffers"][0]["uri"] = std::string(1 << 20, 'b') + ".bin";
  r = hostile_load(j);
  EXPECT_NE(r.status.code, StatusCode::Ok);
  EXPECT_LT(r.status.message.size(), 600u) << r.status.message.substr(0, 200);
  // A million-digit number in an OBJ.
  const std::string obj = "v " + std::string(1000000, '9') + " 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  r = io::load_asset_from_memory(hostile_bytes(obj), Format::Obj, "huge.obj");
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_LT(r.status.message.size(), 600u) << r.status.message.substr(0, 200);
  EXPECT_EQ(io::quote_input(std::string(5000, 'q'), 100).size(), 100u + std::string("... (5000 bytes)").size());
}

TEST(Hostile, WrongComponentTypesAreRefused) {
  nlohmann::json j = hostile_gltf(kQuad, {0, 1, 2});
  j["accessors"][0]["componentType"] = 5121;  // UNSIGNED_BYTE positions without KHR_mesh_quantization
  j["accessors"][0]["count"] = 5;
  io::LoadResult r = hostile_load(j);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("KHR_mesh_quantization"), std::string::npos) << r.status.message;
  j["extensionsUsed"] = {"KHR_mesh_quantization"};
  r = hostile_load(j);
  EXPECT_TRUE(r.status.ok()) << r.status.message.substr(0, 300);  // quantized positions are valid with the extension
  j = hostile_gltf(kQuad, {0, 1, 2});
  j["accessors"][1]["componentType"] = 5122;  // signed SHORT indices
  r = hostile_load(j);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("unsigned integer"), std::string::npos) << r.status.message;
}

TEST(Hostile, SkinsAndAnimationsAreChecked) {
  nlohmann::json j = hostile_gltf(kQuad, {0, 1, 2});
  j["skins"] = {{{"joints", {0, 7}}}};
  io::LoadResult r = hostile_load(j);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("skin 0 joint 1"), std::string::npos) << r.status.message;

  // Sampler input times 0, 1, 1 (not strictly increasing): float times appended to the buffer.
  std::vector<float> data = kQuad;
  const size_t times_at = data.size() * 4;
  data.insert(data.end(), {0.f, 1.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 2.f, 0.f, 0.f});
  j = hostile_gltf(data, {});
  j["bufferViews"][0]["byteLength"] = kQuad.size() * 4;
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", times_at}, {"byteLength", 12}});
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", times_at + 12}, {"byteLength", 36}});
  j["accessors"].push_back({{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "SCALAR"},
                            {"min", {0}}, {"max", {1}}});
  j["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  nlohmann::json animation;
  animation["samplers"] = nlohmann::json::array({{{"input", 1}, {"output", 2}}});
  animation["channels"] = nlohmann::json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}});
  j["animations"] = nlohmann::json::array({animation});
  r = hostile_load(j);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("strictly increasing"), std::string::npos) << r.status.message;
  j["animations"][0]["channels"][0]["target"]["node"] = 9;
  r = hostile_load(j);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("missing sampler or node"), std::string::npos) << r.status.message;
}

TEST(Hostile, TriangleStripsAndFansLoadAsTriangles) {
  // Strip 0 1 2 3 4: triangles (0 1 2), (2 1 3), (2 3 4) — every second one flipped so that all
  // keep the strip's orientation (glTF 2.0 §3.7.2.1).
  nlohmann::json j = hostile_gltf(kQuad, {0, 1, 2, 3, 4});
  j["meshes"][0]["primitives"][0]["mode"] = 5;
  io::LoadResult r = hostile_load(j);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.asset.F_raw.rows(), 3);
  EXPECT_EQ(r.asset.F_raw.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(r.asset.F_raw.row(1), Eigen::RowVector3i(1, 3, 2));
  EXPECT_EQ(r.asset.F_raw.row(2), Eigen::RowVector3i(2, 3, 4));
  // Fan 0 1 2 3: (1 2 0), (2 3 0).
  j = hostile_gltf(kQuad, {0, 1, 3, 2});
  j["meshes"][0]["primitives"][0]["mode"] = 6;
  r = hostile_load(j);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.asset.F_raw.rows(), 2);
  EXPECT_EQ(r.asset.F_raw.row(0), Eigen::RowVector3i(1, 3, 0));
  EXPECT_EQ(r.asset.F_raw.row(1), Eigen::RowVector3i(3, 2, 0));
  // All faces of the strip face +z like the first one (consistent orientation).
  const Eigen::MatrixXd& V = r.asset.V_raw;
  for (int f = 0; f < r.asset.F_raw.rows(); ++f) {
    const Eigen::Vector3d a = V.row(r.asset.F_raw(f, 0)), b = V.row(r.asset.F_raw(f, 1)), c = V.row(r.asset.F_raw(f, 2));
    EXPECT_GT((b - a).cross(c - a).z(), 0) << "fan face " << f;
  }
  // A strip of two vertices is an error, not an empty mesh.
  j = hostile_gltf(kQuad, {0, 1});
  j["meshes"][0]["primitives"][0]["mode"] = 5;
  EXPECT_EQ(hostile_load(j).status.code, StatusCode::ParseError);
}

TEST(Hostile, OnlyRegularFilesAreRead) {
  std::vector<uint8_t> bytes;
  const std::string dir = test::data_path("edit");
  Status s = io::read_file(dir, &bytes);
  EXPECT_EQ(s.code, StatusCode::IoError);
  EXPECT_NE(s.message.find("a directory"), std::string::npos) << s.message;
  const std::string dir_ply = test::scratch_path("hostile_dir.ply");
  ::mkdir(dir_ply.c_str(), 0700);
  const io::LoadResult r = io::load_asset(dir_ply);
  EXPECT_EQ(r.status.code, StatusCode::IoError) << r.status.message;
#ifndef __EMSCRIPTEN__
  const std::string fifo = test::scratch_path("hostile.fifo.obj");
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  s = io::read_file(fifo, &bytes);  // would block forever if opened
  EXPECT_EQ(s.code, StatusCode::IoError);
  EXPECT_NE(s.message.find("pipe"), std::string::npos) << s.message;
  ::unlink(fifo.c_str());
#endif
  EXPECT_EQ(io::read_file(test::scratch_path("no_such_file.ply"), &bytes).code, StatusCode::IoError);
}

TEST(Hostile, WritesAreAtomicAndCheckedFirst) {
  // Writing onto the input's own path: read, then replace in place.
  const std::string path = test::scratch_path("hostile_inplace.off");
  {
    std::ofstream out(path);
    out << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  }
  io::LoadResult r = io::load_asset(path);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_TRUE(io::save_asset(r.asset, r.asset.weld.V * 2.0, path).ok());
  r = io::load_asset(path);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_DOUBLE_EQ(r.asset.V_raw(1, 0), 2.0);
  // No temporary file is left next to it.
  struct stat st;
  EXPECT_NE(::stat((path + ".mm-tmp-" + std::to_string(::getpid())).c_str(), &st), 0);
  // A missing folder or a directory as output: clear errors before any work.
  Status s = io::check_output_path(test::scratch_path("no_such_folder/out.glb"));
  EXPECT_EQ(s.code, StatusCode::IoError);
  EXPECT_NE(s.message.find("does not exist"), std::string::npos) << s.message;
  EXPECT_EQ(io::check_output_path(test::data_path("edit")).code, StatusCode::IoError);
  EXPECT_TRUE(io::check_output_path(test::scratch_path("fine.glb")).ok());
  EXPECT_EQ(io::save_asset(r.asset, r.asset.weld.V, test::scratch_path("no_such_folder/out.off")).code,
            StatusCode::IoError);
}

}  // namespace
}  // namespace mm
