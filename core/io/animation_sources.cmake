# glTF skins/animations and the morph-target animation writer (issue 5, retarget). Included from
# core/io/module.cmake; uses the retarget module's headers (JointSet, SkinWeights), so it is only
# built with that module.
if("retarget" IN_LIST MM_MODULES)
  list(APPEND MM_IO_SOURCES core/io/gltf_animation.cpp core/io/gltf_animation_write.cpp core/io/retarget_session.cpp)
  list(APPEND MM_TEST_SOURCES tests/gltf_animation_test.cpp)
endif()
