// Replays every input kept in tests/bad/<harness>/ (found by the libFuzzer campaigns of issue 13, or
// written by hand for a class the fuzzers must keep covering) through the same reader the harness
// calls (fuzz/fuzz_inputs.h), and checks its specific error: the Status code and a phrase of the
// message. A file in those folders without a row below fails the test, so a new crash input
// cannot be dropped there without saying what it must produce.
#include <gtest/gtest.h>

#include <dirent.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "../fuzz/fuzz_inputs.h"
#include "io/asset.h"
#include "test_support.h"

namespace mm {
namespace {

struct Expected {
  StatusCode code;
  const char* phrase;  // part of the message ("" when the input must load)
};

// tests/bad/<harness>/<file> → what reading it must give.
const std::map<std::string, Expected>& expected_errors() {
  static const std::map<std::string, Expected> table = {
#include "bad/expected_errors.inc"
  };
  return table;
}

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d))
      if (e->d_name[0] != '.') names.push_back(e->d_name);
    ::closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(FuzzRegressions, EveryKeptInputGivesItsError) {
  const std::vector<std::string> harnesses = {"gltf", "glb", "obj", "off", "ply", "edit_spec", "merge_spec", "landmarks", "joints"};
  size_t checked = 0;
  for (const std::string& h : harnesses) {
    for (const std::string& name : list_dir(test::tests_path("bad/" + h))) {
      const std::string key = h + "/" + name;
      SCOPED_TRACE(key);
      const auto it = expected_errors().find(key);
      ASSERT_NE(it, expected_errors().end()) << "tests/bad/" << key << " has no row in tests/bad/expected_errors.inc";
      std::vector<uint8_t> bytes;
      ASSERT_TRUE(io::read_file(test::tests_path("bad/" + key), &bytes).ok());
      const Status s = fuzz::read_input(h, bytes);
      EXPECT_EQ(status_code_name(s.code), std::string(status_code_name(it->second.code))) << s.message;
      EXPECT_NE(s.message.find(it->second.phrase), std::string::npos) << s.message;
      EXPECT_LE(s.message.size(), 600u);
      ++checked;
    }
  }
  // Every row names a file that exists (a renamed file must not leave its row behind).
  EXPECT_EQ(checked, expected_errors().size());
}

}  // namespace
}  // namespace mm
