list(APPEND MM_CORE_SOURCES core/common/status.cpp core/common/progress.cpp core/common/colormap.cpp core/common/process.cpp core/common/threads.cpp)
list(APPEND MM_TEST_SOURCES tests/common_test.cpp)
