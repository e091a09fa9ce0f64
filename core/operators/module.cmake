list(APPEND MM_CORE_SOURCES core/operators/operators.cpp)
