list(APPEND MM_CORE_SOURCES core/metrics/edit_metrics.cpp)
list(APPEND MM_CORE_SOURCES core/metrics/transfer_metrics.cpp)
list(APPEND MM_CORE_SOURCES core/metrics/retarget_metrics.cpp)  # retarget metrics (issue 5)
list(APPEND MM_TEST_SOURCES tests/metrics_test.cpp)
