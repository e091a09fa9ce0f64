list(APPEND MM_CORE_SOURCES core/common/status.cpp core/common/progress.cpp)
