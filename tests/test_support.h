// Shared helpers for the GoogleTest suite: data paths, mesh loading, golden files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/progress.h"
#include "mesh/mesh.h"

namespace mm::test {

// Absolute path of a file under the repository's data/ folder (works natively and in wasm
// under NODERAWFS, where the real file system is visible).
std::string data_path(const std::string& relative);
// Absolute path under tests/ (e.g. "golden/foo.json", "bad/empty.obj").
std::string tests_path(const std::string& relative);
// A scratch directory under the build tree, created on first use.
std::string scratch_path(const std::string& name);

// Loads data/<relative> through mm::io and returns the welded mesh; a load failure is a test
// failure (EXPECT) and gives an empty mesh.
Mesh load_mesh(const std::string& relative);

// "data:application/octet-stream;base64,..." of `data` (glTF buffers embedded in test documents).
std::string data_uri(const std::vector<uint8_t>& data);

// True when the binary was started with --update-golden.
bool update_golden();

// Compares `values` with tests/golden/<name>.json: same shape, max |difference| ≤ the
// tolerance stored in the file. With --update-golden, writes the file instead (storing
// `tolerance`) and passes. The JSON holds {"tolerance", "rows", "cols", "data": row-major}.
void expect_golden(const std::string& name, const Eigen::MatrixXd& values, double tolerance);

// A progress sink that records every report and whether the fraction ever went back (the page's
// bar follows these fractions). It never cancels.
struct ForwardProgress {
  std::vector<std::string> stages;  // consecutive duplicates collapsed
  std::vector<std::string> backwards;  // "stage a at f → stage b at g" for each step back
  double last = 0;
  int reports = 0;
  Progress sink();
};

}  // namespace mm::test
