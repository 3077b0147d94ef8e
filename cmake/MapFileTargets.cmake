# The lossless map file (src/io/map_file.cpp, docs/map_format.md): the build version it records,
# zlib and its tests. Included from CMakeLists.txt after the OctoMap targets.

# io::buildVersion(): generated at every build from package.xml's version and `git describe`
# (cmake/BuildInfo.cmake rewrites the source only when the text changes).
set(ES_BUILD_INFO_CPP "${CMAKE_CURRENT_BINARY_DIR}/generated/build_info.cpp")
set(ES_BUILD_INFO_ARGS
  "-DSOURCE_DIR=${CMAKE_CURRENT_SOURCE_DIR}" "-DVERSION=${evidential_slam_VERSION}"
  "-DOUTPUT=${ES_BUILD_INFO_CPP}" -P "${CMAKE_CURRENT_SOURCE_DIR}/cmake/BuildInfo.cmake")
execute_process(COMMAND "${CMAKE_COMMAND}" ${ES_BUILD_INFO_ARGS})  # exists before the first build
add_custom_target(evidential_slam_build_info
  COMMAND "${CMAKE_COMMAND}" ${ES_BUILD_INFO_ARGS}
  BYPRODUCTS "${ES_BUILD_INFO_CPP}"
  COMMENT "Recording the build version"
  VERBATIM)
target_sources(evidential_slam_io PRIVATE "${ES_BUILD_INFO_CPP}")
add_dependencies(evidential_slam_io evidential_slam_build_info)

find_package(ZLIB REQUIRED)
target_link_libraries(evidential_slam_io PRIVATE ZLIB::ZLIB)

if(CATKIN_ENABLE_TESTING)
  set(MAP_FILE_TEST_DEFINITIONS
    ES_TEST_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/data"
    ES_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}/test_tmp")

  # Format, reader on damaged files, round trip.
  catkin_add_gtest(test_map_file test/io/map_file_test.cpp test/io/test_main.cpp)
  target_link_libraries(test_map_file evidential_slam_io ZLIB::ZLIB)
  target_compile_definitions(test_map_file PRIVATE ${MAP_FILE_TEST_DEFINITIONS})
endif()
endif()
