list(APPEND MM_CORE_SOURCES core/metrics/edit_metrics.cpp)
