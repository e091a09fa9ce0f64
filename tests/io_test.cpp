// Tests of core/io: loading every format from data/, round trips, conversions, malformed input.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "io/asset.h"
#include "io/io_text.h"
#include "mesh/validate.h"
#include "test_support.h"

namespace {

using mm::StatusCode;
using mm::io::Format;
using mm::test::data_path;
using mm::test::scratch_path;
using mm::test::tests_path;

std::vector<uint8_t> io_test_bytes(const std::string& text) { return {text.begin(), text.end()}; }

mm::io::LoadResult io_test_load_text(const std::string& text, Format f, const std::string& name = "mem") {
  return mm::io::load_asset_from_memory(io_test_bytes(text), f, name);
}

double io_test_max_diff(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  if (A.rows() != B.rows() || A.cols() != B.cols()) return INFINITY;
  return (A - B).cwiseAbs().maxCoeff();
}

double io_test_relative_error(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  return io_test_max_diff(A, B) / std::max(mm::bounding_box_diagonal(B), 1e-300);
}

}  // namespace

// ---------------------------------------------------------------- PLY

TEST(IoPly, LoadsBinaryLittleEndianCat) {
  const auto r = mm::io::load_asset(data_path("pose/cat-reference.ply"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.asset.format, Format::Ply);
  EXPECT_EQ(r.asset.V_raw.rows(), 7207);
  EXPECT_EQ(r.asset.F_raw.rows(), 14410);
  EXPECT_EQ(r.asset.weld.V.rows(), 7207);
  ASSERT_EQ(r.asset.primitives.size(), 1u);
  EXPECT_EQ(r.asset.primitives[0].num_faces, 14410);
  EXPECT_TRUE(mm::check_mesh(r.asset.weld.V, r.asset.weld.F).ok());
}

TEST(IoPly, LoadsBar) {
  const auto r = mm::io::load_asset(data_path("edit/bar.ply"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.asset.V_raw.rows(), 354);
  EXPECT_EQ(r.asset.F_raw.rows(), 704);
}

// ---------------------------------------------------------------- OBJ

TEST(IoObj, PolygonsNegativeIndicesAndCornerForms) {
  // A unit square (quad, fan-triangulated) and a triangle with relative indices:
  //   4---3
  //   |   |
  //   1---2
  const std::string obj =
      "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
      "g quad\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf -4//1 -3//1 -1//1\nf 1/1 2/2 3/3\n";
  const auto r = io_test_load_text(obj, Format::Obj);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.asset.V_raw.rows(), 4);
  ASSERT_EQ(r.asset.F_raw.rows(), 4);
  EXPECT_EQ(r.asset.F_raw.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(r.asset.F_raw.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(r.asset.F_raw.row(2), Eigen::RowVector3i(0, 1, 3));
}

TEST(IoObj, WriteBackKeepsOtherLinesAndRecomputesNormals) {
  // Unit square in z=0 as a quad with UVs and one shared normal:
  //   4---3
  //   |   |
  //   1---2
  const std::string obj =
      "# exported by hand\nmtllib square.mtl\no square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng g1\nusemtl red\ns 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n";
  const auto r = io_test_load_text(obj, Format::Obj, "square.obj");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  std::vector<uint8_t> same;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, r.asset.weld.V, Format::Obj, &same).ok());
  EXPECT_EQ(std::string(same.begin(), same.end()), obj) << "unchanged geometry must write back byte for byte";

  // Rotate 90 degrees about x: the square's normal +z becomes -y.
  Eigen::MatrixXd V = r.asset.weld.V;
  for (int i = 0; i < V.rows(); ++i) V.row(i) = Eigen::RowVector3d(V(i, 0), -V(i, 2), V(i, 1));
  std::vector<uint8_t> moved;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, V, Format::Obj, &moved).ok());
  const std::string text(moved.begin(), moved.end());
  EXPECT_NE(text.find("v 0 0 1 0.5 0.5 0.5\n"), std::string::npos) << text;  // extra values kept
  EXPECT_NE(text.find("vn 0 -1 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("usemtl red\ns 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"), std::string::npos) << text;
  const auto back = io_test_load_text(text, Format::Obj);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_LT(io_test_max_diff(back.asset.V_raw, V), 1e-15);
}

TEST(IoObj, RoundTripThroughFileAndConversionKeepsUVs) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  const auto r = io_test_load_text(obj, Format::Obj, "quad.obj");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const std::string path = scratch_path("quad_roundtrip.obj");
  ASSERT_TRUE(mm::io::save_asset(r.asset, r.asset.weld.V * 2.0, path).ok());
  const auto back = mm::io::load_asset(path);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_LT(io_test_max_diff(back.asset.V_raw, r.asset.V_raw * 2.0), 1e-15);
  // OBJ -> GLB keeps the UVs (the glTF convention flips v).
  const std::string glb = scratch_path("roundtrip_quad_from_obj.glb");
  ASSERT_TRUE(mm::io::save_asset(r.asset, r.asset.weld.V, glb).ok());
  const auto g = mm::io::load_asset(glb);
  ASSERT_TRUE(g.status.ok()) << g.status.message;
  EXPECT_EQ(g.asset.V_raw.rows(), 4);
  EXPECT_EQ(g.asset.F_raw, r.asset.F_raw);
  std::vector<uint8_t> obj_again;
  ASSERT_TRUE(mm::io::save_asset_to_memory(g.asset, g.asset.weld.V, Format::Obj, &obj_again).ok());
  const std::string t(obj_again.begin(), obj_again.end());
  EXPECT_NE(t.find("vt 1 1\n"), std::string::npos) << t;
  EXPECT_NE(t.find("f 1/1 2/2 3/3\n"), std::string::npos) << t;
}

// ---------------------------------------------------------------- OFF

TEST(IoOff, CommentsColorsAndPolygons) {
  // A unit square (one quad) plus a triangle on top, with colors (COFF):
  //     4
  //    / \
  //   3---2
  //   |   |
  //   0---1
  const std::string off =
      "COFF\n# a house\n5 2 0\n0 0 0 255 0 0\n1 0 0 255 0 0\n1 1 0 0 255 0\n0 1 0 0 255 0\n"
      "0.5 1.5 0 0 0 255 # roof\n4 0 1 2 3\n\n3 3 2 4 200 10 10\n";
  const auto r = io_test_load_text(off, Format::Off, "house.off");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.asset.V_raw.rows(), 5);
  ASSERT_EQ(r.asset.F_raw.rows(), 3);
  EXPECT_EQ(r.asset.F_raw.row(2), Eigen::RowVector3i(3, 2, 4));
  Eigen::MatrixXd V = r.asset.weld.V;
  V.col(2).array() += 1.0;
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, V, Format::Off, &bytes).ok());
  const std::string text(bytes.begin(), bytes.end());
  EXPECT_EQ(text.rfind("COFF\n# a house\n5 2 0\n", 0), 0u) << text;
  EXPECT_NE(text.find("0.5 1.5 1 0 0 255\n"), std::string::npos) << text;
  EXPECT_NE(text.find("3 3 2 4 200 10 10\n"), std::string::npos) << text;
  const auto back = io_test_load_text(text, Format::Off);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_EQ(back.asset.F_raw, r.asset.F_raw);
  EXPECT_LT(io_test_max_diff(back.asset.V_raw, V), 1e-15);
}

TEST(IoOff, CountsOnKeywordLineAndConversionToPly) {
  const auto r = io_test_load_text("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", Format::Off);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.asset.F_raw.rows(), 1);
  std::vector<uint8_t> ply;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, r.asset.weld.V, Format::Ply, &ply).ok());
  const auto back = mm::io::load_asset_from_memory(ply, Format::Ply, "converted.ply");
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_EQ(back.asset.F_raw, r.asset.F_raw);
  EXPECT_LT(io_test_max_diff(back.asset.V_raw, r.asset.V_raw), 1e-7);
}

// ---------------------------------------------------------------- PLY

namespace {

void io_test_put_be(std::vector<uint8_t>* out, const void* p, size_t n) {
  const auto* b = static_cast<const uint8_t*>(p);
  for (size_t i = 0; i < n; ++i) out->push_back(b[n - 1 - i]);
}

}  // namespace

TEST(IoPly, BinaryWriteBackIsByteIdenticalWhenUnchanged) {
  std::vector<uint8_t> original;
  ASSERT_TRUE(mm::io::read_file(data_path("pose/cat-reference.ply"), &original).ok());
  const auto r = mm::io::load_asset(data_path("pose/cat-reference.ply"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, r.asset.weld.V, Format::Ply, &bytes).ok());
  EXPECT_TRUE(bytes == original);
  // Moved positions come back (float storage).
  const Eigen::MatrixXd V = r.asset.weld.V * 0.5;
  ASSERT_TRUE(mm::io::save_asset(r.asset, V, scratch_path("cat_half.ply")).ok());
  const auto back = mm::io::load_asset(scratch_path("cat_half.ply"));
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_EQ(back.asset.F_raw, r.asset.F_raw);
  EXPECT_LT(io_test_max_diff(back.asset.V_raw, V) / mm::bounding_box_diagonal(V), 1e-7);
}

TEST(IoPly, AsciiExtraPropertiesAndPolygonsSurviveWriteBack) {
  // Quad + triangle, per-vertex normal, color and quality; face list named vertex_index with
  // int counts and a per-face flag.
  const std::string ply =
      "ply\nformat ascii 1.0\ncomment hand made\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nproperty double quality\nelement face 2\n"
      "property list int int vertex_index\nproperty uchar flags\nend_header\n"
      "0 0 0 0 0 1 255 0 0 0.25\n1 0 0 0 0 1 255 0 0 0.5\n1 1 0 0 0 1 0 255 0 0.75\n0 1 0 0 0 1 0 255 0 1\n"
      "0.5 1.5 0 0 0 1 0 0 255 1.25\n4 0 1 2 3 7\n3 3 2 4 9\n";
  const auto r = io_test_load_text(ply, Format::Ply, "house.ply");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.asset.V_raw.rows(), 5);
  EXPECT_EQ(r.asset.F_raw.rows(), 3);
  std::vector<uint8_t> same;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, r.asset.weld.V, Format::Ply, &same).ok());
  EXPECT_EQ(std::string(same.begin(), same.end()), ply);
  // Rotate about x by 90 degrees: normals follow (+z -> -y), colors/quality/flags stay.
  Eigen::MatrixXd V = r.asset.weld.V;
  for (int i = 0; i < V.rows(); ++i) V.row(i) = Eigen::RowVector3d(V(i, 0), -V(i, 2), V(i, 1));
  std::vector<uint8_t> moved;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, V, Format::Ply, &moved).ok());
  const std::string text(moved.begin(), moved.end());
  EXPECT_NE(text.find("\n0.5 0 1.5 0 -1 0 0 0 255 1.25\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\n4 0 1 2 3 7\n3 3 2 4 9\n"), std::string::npos) << text;
  // Conversion keeps colors (PLY -> GLB COLOR_0 -> PLY red/green/blue).
  std::vector<uint8_t> glb;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, r.asset.weld.V, Format::Glb, &glb).ok());
  const auto g = mm::io::load_asset_from_memory(glb, Format::Glb, "house.glb");
  ASSERT_TRUE(g.status.ok()) << g.status.message;
  std::vector<uint8_t> ply2;
  ASSERT_TRUE(mm::io::save_asset_to_memory(g.asset, g.asset.weld.V, Format::Ply, &ply2).ok());
  const auto p2 = mm::io::load_asset_from_memory(ply2, Format::Ply, "again.ply");
  ASSERT_TRUE(p2.status.ok()) << p2.status.message;
  EXPECT_EQ(p2.asset.F_raw, r.asset.F_raw);
  const std::string header(ply2.begin(), ply2.begin() + 400);
  EXPECT_NE(header.find("property uchar red"), std::string::npos);
}

TEST(IoPly, BigEndianDoublesAndUintCounts) {
  // One triangle, big endian, double coordinates, uint list counts, uint indices, an extra
  // short property per vertex.
  std::vector<uint8_t> b;
  const std::string header =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\nproperty short id\nelement face 1\nproperty list uint uint vertex_indices\nend_header\n";
  b.insert(b.end(), header.begin(), header.end());
  const double xyz[3][3] = {{0.1, 0.2, 0.3}, {1.5, 0, 0}, {0, 2.5, 0}};
  for (int v = 0; v < 3; ++v) {
    for (int c = 0; c < 3; ++c) io_test_put_be(&b, &xyz[v][c], 8);
    const int16_t id = static_cast<int16_t>(-7 * v);
    io_test_put_be(&b, &id, 2);
  }
  const uint32_t face[4] = {3, 2, 1, 0};
  for (uint32_t k : face) io_test_put_be(&b, &k, 4);
  const auto r = mm::io::load_asset_from_memory(b, Format::Ply, "be.ply");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.asset.V_raw(0, 0), 0.1);
  EXPECT_EQ(r.asset.V_raw(2, 1), 2.5);
  EXPECT_EQ(r.asset.F_raw.row(0), Eigen::RowVector3i(2, 1, 0));
  std::vector<uint8_t> same;
  ASSERT_TRUE(mm::io::save_asset_to_memory(r.asset, r.asset.weld.V, Format::Ply, &same).ok());
  EXPECT_TRUE(same == b);
}

// ---------------------------------------------------------------- conversions

TEST(IoConvert, PlyToGlbAndOffKeepGeometry) {
  const auto r = mm::io::load_asset(data_path("pose/cat-reference.ply"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  for (const char* name : {"roundtrip_cat_from_ply.glb", "cat_from_ply.gltf", "cat_from_ply.off", "cat_from_ply.obj"}) {
    SCOPED_TRACE(name);
    const std::string out = scratch_path(name);
    ASSERT_TRUE(mm::io::save_asset(r.asset, r.asset.weld.V, out).ok());
    const auto back = mm::io::load_asset(out);
    ASSERT_TRUE(back.status.ok()) << back.status.message;
    EXPECT_EQ(back.asset.F_raw, r.asset.F_raw);
    EXPECT_LT(io_test_max_diff(back.asset.V_raw, r.asset.V_raw), 1e-12);  // float data: exact
  }
}

// ---------------------------------------------------------------- malformed input

TEST(IoBad, EachClassHasItsError) {
  struct Case { const char* file; StatusCode code; const char* message; };
  const Case cases[] = {
      {"empty.obj", StatusCode::ParseError, "file is empty"},
      {"empty.off", StatusCode::ParseError, "file is empty"},
      {"empty.ply", StatusCode::ParseError, "file is empty"},
      {"empty.gltf", StatusCode::ParseError, "file is empty"},
      {"empty.glb", StatusCode::ParseError, "file is empty"},
      {"truncated.glb", StatusCode::ParseError, "truncated GLB"},
      {"bad_json.gltf", StatusCode::ParseError, "invalid glTF JSON"},
      {"index_out_of_range.gltf", StatusCode::ParseError, "is 5 but POSITION has only 3 vertices"},
      {"accessor_overrun.gltf", StatusCode::ParseError, "overrun bufferView"},
      {"missing_bin.gltf", StatusCode::IoError, "missing file 'missing.bin'"},
      {"lines.gltf", StatusCode::Unsupported, "uses mode LINES"},
      {"traversal_dotdot.gltf", StatusCode::IoError, "'..' path segments are refused"},
      {"traversal_encoded.gltf", StatusCode::IoError, "'..' path segments are refused"},
      {"traversal_absolute.gltf", StatusCode::IoError, "absolute paths are refused"},
      {"traversal_scheme.gltf", StatusCode::IoError, "URI schemes other than data: are refused"},
      {"header_lies_binary.ply", StatusCode::ParseError, "declares 100 vertex elements"},
      {"header_lies_ascii.ply", StatusCode::ParseError, "declares 10 vertex elements"},
      {"index_out_of_range.ply", StatusCode::ParseError, "references vertex 7 but there are 3 vertices"},
      {"vertex_zero.obj", StatusCode::ParseError, "vertex 0, but OBJ indices start at 1"},
      {"vertex_beyond.obj", StatusCode::ParseError, "references vertex 4 but only 3 vertices"},
      {"short.off", StatusCode::ParseError, "declares 8 vertices"},
      {"index_out_of_range.off", StatusCode::ParseError, "references vertex 3 but there are 3 vertices"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const auto r = mm::io::load_asset(tests_path(std::string("bad/") + c.file));
    EXPECT_EQ(r.status.code, c.code) << mm::status_code_name(r.status.code) << ": " << r.status.message;
    EXPECT_NE(r.status.message.find(c.message), std::string::npos) << r.status.message;
    EXPECT_EQ(r.asset.V_raw.rows(), 0);
  }
  // The GLB the truncated one was cut from is fine.
  EXPECT_TRUE(mm::io::load_asset(tests_path("bad/triangle_ok.glb")).status.ok());
}

TEST(IoBad, NanCoordinatesLoadAndAreReportedByValidation) {
  const auto r = mm::io::load_asset(tests_path("bad/nan.obj"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const mm::MeshReport report = mm::validate_mesh(r.asset.weld.V, r.asset.weld.F);
  EXPECT_EQ(report.count(mm::MeshDefect::NonFiniteCoordinate), 1);
  // ... and are never written out.
  std::vector<uint8_t> bytes;
  EXPECT_EQ(mm::io::save_asset_to_memory(r.asset, r.asset.weld.V, Format::Glb, &bytes).code,
            StatusCode::NumericalError);
}

TEST(IoBad, UnknownExtensionMissingFileAndWrongShapes) {
  EXPECT_EQ(mm::io::load_asset(tests_path("bad/README.md")).status.code, StatusCode::Unsupported);
  const auto missing = mm::io::load_asset(tests_path("bad/does_not_exist.ply"));
  EXPECT_EQ(missing.status.code, StatusCode::IoError);
  EXPECT_NE(missing.status.message.find("does_not_exist.ply"), std::string::npos);
  const auto r = mm::io::load_asset(tests_path("bad/triangle_ok.glb"));
  ASSERT_TRUE(r.status.ok());
  std::vector<uint8_t> bytes;
  EXPECT_EQ(mm::io::save_asset_to_memory(r.asset, Eigen::MatrixXd::Zero(2, 3), Format::Glb, &bytes).code,
            StatusCode::InvalidArgument);
  Eigen::MatrixXi F(1, 3);
  F << 0, 1, 9;
  EXPECT_EQ(mm::io::save_mesh_to_memory(Format::Ply, Eigen::MatrixXd::Zero(3, 3), F, &bytes).code,
            StatusCode::InvalidArgument);
}

TEST(IoBad, GarbageNeverCrashes) {
  // Every prefix of a valid file, for every format: any Status is fine, a crash is not.
  std::vector<std::pair<std::string, Format>> sources = {
      {tests_path("bad/triangle_ok.glb"), Format::Glb},
      {tests_path("bad/index_out_of_range.gltf"), Format::Gltf},
      {tests_path("bad/index_out_of_range.ply"), Format::Ply},
      {tests_path("bad/header_lies_binary.ply"), Format::Ply},
      {tests_path("bad/index_out_of_range.off"), Format::Off},
      {tests_path("bad/vertex_beyond.obj"), Format::Obj}};
  for (const auto& [path, format] : sources) {
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(mm::io::read_file(path, &bytes).ok());
    for (size_t n = 0; n <= bytes.size(); ++n) {
      const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + n);
      const auto r = mm::io::load_asset_from_memory(prefix, format, path);
      if (!r.status.ok()) EXPECT_FALSE(r.status.message.empty());
    }
    // Flipped bytes, too.
    for (size_t i = 0; i < bytes.size(); ++i) {
      std::vector<uint8_t> flipped = bytes;
      flipped[i] ^= 0xA5;
      (void)mm::io::load_asset_from_memory(flipped, format, path);
    }
  }
}

TEST(IoConvert, SaveMeshGlbWithColorsValidates) {
  const auto r = mm::io::load_asset(data_path("edit/bar.ply"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const Eigen::MatrixXd& V = r.asset.weld.V;
  Eigen::MatrixXd C = (V.rowwise() - V.colwise().minCoeff()).array().rowwise() /
                      (V.colwise().maxCoeff() - V.colwise().minCoeff()).array().max(1e-12);
  const std::string out = scratch_path("save_mesh_bar_colors.glb");
  const mm::Status s = mm::io::save_mesh(out, V, r.asset.weld.F, C);
  ASSERT_TRUE(s.ok()) << s.message;
  const auto back = mm::io::load_asset(out);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_EQ(back.asset.V_raw.rows(), V.rows());
  EXPECT_EQ(back.asset.F_raw, r.asset.weld.F);
  EXPECT_LT(io_test_relative_error(back.asset.V_raw, V), 1e-6);
  // Without colors, too.
  ASSERT_TRUE(mm::io::save_mesh(scratch_path("save_mesh_bar.glb"), V, r.asset.weld.F).ok());
}

TEST(IoConvert, GltfToObjKeepsUVsAndRawLayout) {
  const auto r = mm::io::load_asset(data_path("anim/Fox/glTF-Binary/Fox.glb"));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const std::string out = scratch_path("fox_from_glb.obj");
  ASSERT_TRUE(mm::io::save_asset(r.asset, r.asset.weld.V, out).ok());
  const auto back = mm::io::load_asset(out);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_EQ(back.asset.V_raw, r.asset.V_raw);  // float values print and parse exactly
  EXPECT_EQ(back.asset.F_raw, r.asset.F_raw);
  EXPECT_EQ(back.asset.weld.V.rows(), 290);
  std::vector<uint8_t> text;
  ASSERT_TRUE(mm::io::read_file(out, &text).ok());
  const std::string s(text.begin(), text.end());
  EXPECT_NE(s.find("\nvt "), std::string::npos);
  EXPECT_NE(s.find("\nf 1/1 2/2 3/3\n"), std::string::npos);
}

// ---------------------------------------------------------------- number tokens

// The readers' double parsing (io_text.cpp: Clinger's fast path, strtod otherwise) must give
// strtod's value bit for bit and accept exactly what strtod accepts as a whole token.
TEST(IoText, NumbersReadExactlyAsStrtod) {
  auto reference = [](const std::string& t, double* v) {
    if (t.empty()) return false;
    char* end = nullptr;
    errno = 0;
    *v = std::strtod(t.c_str(), &end);
    return end == t.c_str() + t.size() && !(errno == ERANGE && std::isinf(*v));
  };
  std::vector<std::string> tokens = {"0", "-0", "-0.0", "+0.5", ".5", "5.", "-.5e1", "1e22", "1e23", "1e-22", "1e-23",
                                     "9007199254740992", "9007199254740993", "123456789012345678", "1234567890123456789",
                                     "0.000000000000000000000000001", "00000000000000000000001.5", "1.5e+0003", "1E5",
                                     "4.35", "0.1", "0.3", "2.2250738585072014e-308", "1.7976931348623157e308", "1e400",
                                     "1e-400", "0e99999", "1e", "e5", ".", "-", "--1", "1.2.3", "1e5.5", "nan", "inf",
                                     "-inf", "0x1p3", "1,5", " 1", "1 ", "112.863998", "-0.224207"};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exp10(-30, 30);
  char buf[64];
  for (int i = 0; i < 20000; ++i) {
    const double x = unit(rng) * std::pow(10.0, exp10(rng));
    static const char* const formats[] = {"%.6f", "%.9g", "%.15g", "%.17g", "%e", "%.3e", "%.12f"};
    std::snprintf(buf, sizeof(buf), formats[i % 7], x);
    tokens.push_back(buf);
  }
  int fast_agree = 0;
  for (const std::string& t : tokens) {
    double want = 0, got = 0;
    const bool ok_want = reference(t, &want);
    const bool ok_got = mm::io::detail::parse_double_token(t, &got);
    ASSERT_EQ(ok_got, ok_want) << "'" << t << "'";
    if (!ok_want) continue;
    ASSERT_EQ(std::memcmp(&want, &got, sizeof(double)), 0) << "'" << t << "': " << want << " vs " << got;
    ++fast_agree;
  }
  EXPECT_GT(fast_agree, 20000);
}
