list(APPEND MM_CORE_SOURCES core/linalg/spd_solver.cpp core/linalg/polar.cpp core/linalg/rigid_fit.cpp core/linalg/supernodal_cholesky.cpp core/linalg/iterative_refinement.cpp core/linalg/block_lanczos.cpp core/linalg/wasm_eigen_kernels.cpp)
list(APPEND MM_TEST_SOURCES tests/linalg_test.cpp)
