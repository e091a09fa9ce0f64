list(APPEND MM_CORE_SOURCES core/mesh/mesh.cpp core/mesh/topology.cpp core/mesh/validate.cpp core/mesh/weld.cpp core/mesh/butterfly.cpp
     core/mesh/midpoint_subdivide.cpp)
list(APPEND MM_TEST_SOURCES tests/mesh_test.cpp tests/weld_test.cpp)
