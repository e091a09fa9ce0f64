list(APPEND MM_CORE_SOURCES core/operators/operators.cpp)
list(APPEND MM_TEST_SOURCES tests/operators_test.cpp)
