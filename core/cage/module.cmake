# core/cage: automatic enclosing cage (offset surface + progressive-hull decimation), cage
# containment, mean-value coordinates. Owned by the transfer work (issue 4); retarget reuses it.
list(APPEND MM_CORE_SOURCES
  core/cage/cage_detail.cpp
  core/cage/offset_surface.cpp
  core/cage/hull_decimation.cpp
  core/cage/cage_containment.cpp
  core/cage/enclosing_cage.cpp
  core/cage/mean_value_coordinates.cpp)
list(APPEND MM_TEST_SOURCES tests/cage_test.cpp tests/hull_decimation_test.cpp tests/offset_surface_test.cpp)
