list(APPEND MM_CORE_SOURCES core/spectral/spectral_basis.cpp)
