// Huge inputs (issue 13), natively: a mesh of over a million vertices goes through what
// `meshmorph info` and `meshmorph convert` do (load_asset, info_report, save_asset) in seconds, and a
// file over the 2000 MiB limit (a sparse file: no disk is used) is refused before any of it is read,
// on every path that reads a user's file: meshes, a .gltf's external buffer, landmark files, edit
// specs (and joint files, which the CLI reads with the same io::read_file).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <unordered_map>

#include "app/edit_job.h"
#include "io/asset.h"
#include "io/info_report.h"
#include "io/landmarks_file.h"
#include "mesh/midpoint_subdivide.h"
#include "test_support.h"

namespace mm {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}


TEST(HugeInputs, MillionVertexMeshIsLoadedReportedAndConverted) {
#ifdef __EMSCRIPTEN__
  GTEST_SKIP() << "native: the page's memory limits are the page's tests";
#endif
  Mesh m = test::load_mesh("pose/camel_ref.ply");  // 21887 vertices → 1.4 M after three splits
  while (m.V.rows() < 1000000) m = midpoint_subdivide(m);
  const std::string ply = test::scratch_path("huge_1m.ply"), glb = test::scratch_path("huge_1m.glb");
  ASSERT_TRUE(io::save_mesh(ply, m.V, m.F).ok());

  auto t0 = std::chrono::steady_clock::now();
  const io::LoadResult r = io::load_asset(ply);  // meshmorph info
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const double load_s = seconds_since(t0);
  EXPECT_EQ(r.asset.V_raw.rows(), m.V.rows());
  EXPECT_EQ(r.asset.weld.F.rows(), m.F.rows());
  t0 = std::chrono::steady_clock::now();
  const io::InfoReport info = io::info_report(r.asset);
  const double info_s = seconds_since(t0);
  EXPECT_NE(info.text.find(std::to_string(m.V.rows())), std::string::npos) << info.text;
  t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(io::save_asset(r.asset, r.asset.weld.V, glb).ok());  // meshmorph convert
  const double save_s = seconds_since(t0);
  const io::LoadResult back = io::load_asset(glb);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_EQ(back.asset.weld.V.rows(), m.V.rows());
  std::printf("[ HUGE ] %d vertices, %d faces: load %.2f s, info %.2f s, convert to GLB %.2f s\n",
              static_cast<int>(m.V.rows()), static_cast<int>(m.F.rows()), load_s, info_s, save_s);
  if (!std::getenv("MM_KEEP_HUGE")) {  // set it to time `meshmorph info/convert` on the files by hand
    std::remove(ply.c_str());
    std::remove(glb.c_str());
  }
}

// A sparse file of `bytes` bytes (nothing written, so no disk is used).
bool sparse_file(const std::string& path, uint64_t bytes) {
  const int fd = ::open(path.c_str(), O_CREAT | O_TRUNC | O_WRONLY, 0600);
  if (fd < 0) return false;
  const bool ok = ::ftruncate(fd, static_cast<off_t>(bytes)) == 0;
  ::close(fd);
  return ok;
}

TEST(HugeInputs, FilesOverTheLimitAreRefusedBeforeReading) {
#ifdef __EMSCRIPTEN__
  GTEST_SKIP() << "native: the page's memory limits are the page's tests";
#endif
  const uint64_t size = io::kMaxInputBytes + (1u << 20);  // 2001 MiB
  const auto t0 = std::chrono::steady_clock::now();
  auto expect_refused = [&](const Status& s, const std::string& what) {
    EXPECT_EQ(s.code, StatusCode::Unsupported) << what << ": " << s.message;
    EXPECT_NE(s.message.find("files over 2000 MiB are refused"), std::string::npos) << what << ": " << s.message;
  };
  for (const char* ext : {"ply", "obj", "off", "glb", "gltf"}) {
    const std::string path = test::scratch_path(std::string("huge_sparse.") + ext);
    ASSERT_TRUE(sparse_file(path, size));
    expect_refused(io::load_asset(path).status, ext);
    std::remove(path.c_str());
  }
  // A small .gltf whose external buffer is over the limit.
  const std::string bin = test::scratch_path("huge_buffer.bin"), gltf = test::scratch_path("huge_buffer.gltf");
  ASSERT_TRUE(sparse_file(bin, size));
  {
    std::ofstream out(gltf);
    out << R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36, "uri": "huge_buffer.bin"}],
               "bufferViews": [{"buffer": 0, "byteLength": 36}],
               "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
               "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "nodes": [{"mesh": 0}],
               "scenes": [{"nodes": [0]}]})";
  }
  expect_refused(io::load_asset(gltf).status, "external buffer");
  std::remove(bin.c_str());
  std::remove(gltf.c_str());
  // Landmarks and edit specs.
  const std::string json = test::scratch_path("huge_sparse.json");
  ASSERT_TRUE(sparse_file(json, size));
  std::vector<LandmarkPair> pairs;
  expect_refused(io::read_landmarks(json, &pairs), "landmarks");
  app::EditJobRequest edit;
  edit.files = {test::data_path("edit/bar.ply"), json, test::scratch_path("huge_edit_out.ply")};
  expect_refused(app::run_edit_job(edit).status, "edit spec");
  std::remove(json.c_str());
  EXPECT_LT(seconds_since(t0), 5.0) << "refusing must not read the files";
}

}  // namespace
}  // namespace mm
