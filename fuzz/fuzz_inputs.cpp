// The body shared by every fuzz_<harness> binary: fuzz_inputs.h's read_input.
#include "fuzz_inputs.h"

int mm_fuzz_read(const char* harness, const uint8_t* data, size_t size) {
  mm::fuzz::read_input(harness, std::vector<uint8_t>(data, data + size));
  return 0;
}
