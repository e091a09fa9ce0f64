# Dependencies, all from Debian packages (see README.md / scripts/setup):
#   Eigen 3.4 (libeigen3-dev), Spectra 1.0 (libspectra-dev), tinygltf 2.7 (libtinygltf-dev, header-only
#   here), nlohmann-json 3.11 (nlohmann-json3-dev), stb (libstb-dev), GoogleTest 1.12 (/usr/src/googletest).
#
# The same header-only route serves both targets. Under emcmake, find_package cannot see /usr
# (CMAKE_FIND_ROOT_PATH_MODE_PACKAGE=ONLY) and -I/usr/include must never reach em++, so every
# header dependency is exposed through a shim folder of symlinks in the build tree.
if(TARGET mm::eigen)
  return()
endif()

set(MM_SHIM ${CMAKE_BINARY_DIR}/shim)
file(MAKE_DIRECTORY ${MM_SHIM})
foreach(pair
    "Eigen=/usr/include/eigen3/Eigen"
    "unsupported=/usr/include/eigen3/unsupported"
    "Spectra=/usr/include/Spectra"
    "nlohmann=/usr/include/nlohmann"
    "tiny_gltf.h=/usr/include/tiny_gltf.h"
    "stb_image.h=/usr/include/stb/stb_image.h"
    "stb_image_write.h=/usr/include/stb/stb_image_write.h")
  string(REPLACE "=" ";" kv ${pair})
  list(GET kv 0 name)
  list(GET kv 1 target)
  if(NOT EXISTS ${target})
    message(FATAL_ERROR "${target} is missing: run scripts/setup (installs the Debian packages)")
  endif()
  if(NOT EXISTS ${MM_SHIM}/${name})
    file(CREATE_LINK ${target} ${MM_SHIM}/${name} SYMBOLIC)
  endif()
endforeach()

add_library(mm_eigen INTERFACE)
target_include_directories(mm_eigen SYSTEM INTERFACE ${MM_SHIM})
target_compile_definitions(mm_eigen INTERFACE EIGEN_MPL2_ONLY)
if(EMSCRIPTEN)
  # Eigen's double GEMV has wasm SIMD kernels of ours (core/linalg/wasm_eigen_kernels.h): the explicit
  # specialisations must be declared before any use, so every C++ TU that sees Eigen includes the
  # declarations first.
  target_compile_options(mm_eigen INTERFACE
    "$<$<COMPILE_LANGUAGE:CXX>:SHELL:-include ${PROJECT_SOURCE_DIR}/core/linalg/wasm_eigen_kernels.h>")
endif()
add_library(mm::eigen ALIAS mm_eigen)

add_library(mm_spectra INTERFACE)
target_link_libraries(mm_spectra INTERFACE mm_eigen)
add_library(mm::spectra ALIAS mm_spectra)

# tinygltf without stb image decoding: meshes only; images are kept as opaque bytes/URIs and
# written back unchanged. The macros must be visible in every TU that includes tiny_gltf.h.
add_library(mm_tinygltf INTERFACE)
target_link_libraries(mm_tinygltf INTERFACE mm_eigen)
target_compile_definitions(mm_tinygltf INTERFACE
  TINYGLTF_NO_STB_IMAGE TINYGLTF_NO_STB_IMAGE_WRITE TINYGLTF_NO_EXTERNAL_IMAGE TINYGLTF_USE_CPP14)
add_library(mm::tinygltf ALIAS mm_tinygltf)

if(MM_BUILD_TESTS AND NOT TARGET gtest)
  set(gtest_disable_pthreads ON CACHE BOOL "" FORCE)
  set(BUILD_GMOCK OFF CACHE BOOL "" FORCE)
  set(INSTALL_GTEST OFF CACHE BOOL "" FORCE)
  add_subdirectory(/usr/src/googletest ${CMAKE_BINARY_DIR}/googletest EXCLUDE_FROM_ALL)
endif()
