# core/io: the Asset loader/saver (asset.h) and one reader/writer pair per format.
list(APPEND MM_IO_SOURCES
  core/io/asset.cpp
  core/io/io_text.cpp
  core/io/json_text.cpp
  core/io/obj.cpp
  core/io/off.cpp
  core/io/ply.cpp
  core/io/gltf_uri.cpp
  core/io/gltf_accessor.cpp
  core/io/gltf_builder.cpp
  core/io/gltf_load.cpp
  core/io/gltf_serialize.cpp
  core/io/gltf_save.cpp
  core/io/gltf_export.cpp
  core/io/tinygltf_impl.cpp)
list(APPEND MM_TEST_SOURCES tests/io_test.cpp tests/io_gltf_test.cpp tests/io_hostile_test.cpp
  tests/io_fuzz_regressions_test.cpp tests/io_huge_test.cpp)
list(APPEND MM_IO_SOURCES core/io/info_report.cpp)  # owned by the lead: the `info` report shared by CLI and wasm
# glTF skins/animations (read into core/character types) and the morph-target animation writer.
list(APPEND MM_IO_SOURCES core/io/gltf_animation.cpp core/io/gltf_animation_write.cpp core/io/joints_json.cpp)
list(APPEND MM_TEST_SOURCES tests/gltf_animation_test.cpp tests/morph_export_test.cpp)
list(APPEND MM_IO_SOURCES core/io/landmarks_file.cpp core/io/parts_file.cpp core/io/debug_lines_glb.cpp)
