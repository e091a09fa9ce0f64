# core/transfer: spectral pose transfer (paper 000, issue 4). Baselines live in pose_transfer.cpp.
list(APPEND MM_CORE_SOURCES core/transfer/cage_pose_solver.cpp core/transfer/pose_transfer.cpp core/transfer/part_transfer.cpp core/transfer/flip_repair.cpp)
list(APPEND MM_TEST_SOURCES tests/transfer_test.cpp tests/part_transfer_test.cpp tests/flip_repair_test.cpp)
