// Test entry point: GoogleTest plus `--update-golden`, which rewrites tests/golden/*.json
// from the current results instead of comparing (commit the diff with a reason).
#include <cstring>

#include <gtest/gtest.h>

namespace mm::test {
void set_update_golden(bool on);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--update-golden") == 0) mm::test::set_update_golden(true);
  return RUN_ALL_TESTS();
}
