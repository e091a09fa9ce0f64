list(APPEND MM_CORE_SOURCES core/edit/selection.cpp core/edit/implicit_gradients.cpp core/edit/laplacian_editor.cpp core/edit/edit_region.cpp core/edit/similarity_system.cpp core/edit/handle_basis.cpp core/edit/finalize_system.cpp core/edit/shear_removal.cpp)
list(APPEND MM_TEST_SOURCES tests/edit_test.cpp tests/edit_precision_test.cpp)
