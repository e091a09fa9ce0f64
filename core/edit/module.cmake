list(APPEND MM_CORE_SOURCES core/edit/selection.cpp core/edit/implicit_gradients.cpp core/edit/laplacian_editor.cpp core/edit/supernodal_cholesky.cpp core/edit/shear_removal.cpp)
list(APPEND MM_TEST_SOURCES tests/edit_test.cpp)
