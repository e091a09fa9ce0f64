list(APPEND MM_CORE_SOURCES core/linalg/spd_solver.cpp core/linalg/polar.cpp)
