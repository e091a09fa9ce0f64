list(APPEND MM_CORE_SOURCES
  core/retarget/mfs_kernel.cpp
  core/retarget/harmonic_map.cpp
  core/retarget/bone_correspondence.cpp
  core/retarget/harmonic_synthesis.cpp
  core/retarget/harmonic_retarget.cpp
  core/retarget/context_graph.cpp
  core/retarget/nonrigid_icp.cpp
  core/retarget/bone_blend.cpp
  core/retarget/harmonic_retarget_graph.cpp
  core/retarget/lbs_baseline.cpp
  core/retarget/ball_parts.cpp
  core/retarget/curve_skeleton.cpp
  core/retarget/joint_fitting.cpp)
list(APPEND MM_TEST_SOURCES tests/retarget_test.cpp tests/joint_fitting_test.cpp tests/context_graph_test.cpp)
