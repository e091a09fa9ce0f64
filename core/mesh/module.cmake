list(APPEND MM_CORE_SOURCES core/mesh/mesh.cpp core/mesh/topology.cpp core/mesh/validate.cpp core/mesh/weld.cpp)
