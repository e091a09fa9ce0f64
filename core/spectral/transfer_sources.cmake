# Spectral pieces of pose transfer (issue 4): landmark functions and coupled quasi-harmonic bases.
list(APPEND MM_CORE_SOURCES core/spectral/landmarks.cpp core/spectral/coupled_bases.cpp)
list(APPEND MM_TEST_SOURCES tests/coupled_bases_test.cpp tests/landmarks_test.cpp)
