list(APPEND MM_CORE_SOURCES core/spatial/triangle_bvh.cpp core/spatial/farthest_point_sampling.cpp
  core/spatial/quadric.cpp core/spatial/uniform_grid.cpp core/spatial/self_intersections.cpp)
list(APPEND MM_TEST_SOURCES tests/spatial_test.cpp)
