list(APPEND MM_IO_SOURCES core/io/asset_stub_for_build.cpp)
