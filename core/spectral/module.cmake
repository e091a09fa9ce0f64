list(APPEND MM_CORE_SOURCES core/spectral/spectral_basis.cpp)
list(APPEND MM_TEST_SOURCES tests/spectral_test.cpp)
include(core/spectral/transfer_sources.cmake)
