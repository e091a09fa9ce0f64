// The libFuzzer entry of fuzz_<MM_FUZZ_HARNESS> (one tiny TU per harness; the work is compiled once
// in fuzz_inputs.cpp).
#include <cstddef>
#include <cstdint>

int mm_fuzz_read(const char* harness, const uint8_t* data, size_t size);

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return mm_fuzz_read(MM_FUZZ_HARNESS, data, size);
}
