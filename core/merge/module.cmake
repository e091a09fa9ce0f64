list(APPEND MM_CORE_SOURCES core/merge/cut.cpp core/merge/mesh_merge.cpp core/merge/seam_zip.cpp core/merge/transition.cpp)
list(APPEND MM_TEST_SOURCES tests/merge_test.cpp)
