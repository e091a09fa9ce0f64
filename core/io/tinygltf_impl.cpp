// The one translation unit that compiles tinygltf's implementation (slow; kept out of unity
// batches by the top-level CMakeLists). Image decoding is off (TINYGLTF_NO_STB_IMAGE and
// friends come from the mm::tinygltf target): images pass through as encoded bytes.
#define TINYGLTF_IMPLEMENTATION
#include "io/gltf_document.h"
