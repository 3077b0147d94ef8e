# The lossless map file (src/io/map_file.cpp, docs/map_format.md): the build version it records,
# zlib, its tests and the reader's libFuzzer target. Included from CMakeLists.txt after the
# OctoMap targets (whose clang probe the fuzzer reuses).

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

  # Mapping the fixture in one go and in two halves through a saved file (the session library is
  # defined after this file is included; CMake resolves the name at generation).
  catkin_add_gtest(test_map_continue test/io/map_continue_test.cpp test/io/test_main.cpp)
  target_link_libraries(test_map_continue evidential_slam_session)
  target_compile_definitions(test_map_continue PRIVATE ${MAP_FILE_TEST_DEFINITIONS}
    ES_CONFIG_DIR="${CMAKE_CURRENT_SOURCE_DIR}/config")

  # --- libFuzzer target for the reader -----------------------------------------------------------
  # Built like the OctoMap reader's (OctomapTargets.cmake): with clang, ASan and UBSan, when that
  # file's probe found a clang++ that links -fsanitize=fuzzer (it then set ES_FUZZER_BIN).
  # test_map_file_fuzz runs it for a fixed number of inputs from the committed seeds
  # (test/data/map_file_seeds).
  set(ES_MAP_FUZZER_BIN "")
  if(ES_FUZZER_BIN)
    set(ES_MAP_FUZZER_BIN "${CMAKE_CURRENT_BINARY_DIR}/map_file_fuzzer")
    set(map_fuzz_sources
      "${CMAKE_CURRENT_SOURCE_DIR}/test/io/map_file_fuzzer.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/io/map_file.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/io/atomic_files.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/io/error_text.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/core/evidential_grid.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/core/mass.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/core/pose2.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/core/profile.cpp"
      "${ES_BUILD_INFO_CPP}")
    file(GLOB map_fuzz_headers CONFIGURE_DEPENDS
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/io/map_file.h"
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/io/atomic_files.h"
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/core/evidential_grid.h"
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/core/mass.h"
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/core/pose2.h"
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/core/profile.h")
    add_custom_command(OUTPUT "${ES_MAP_FUZZER_BIN}"
      COMMAND "${ES_CLANGXX}" -std=c++17 -O1 -g -fno-omit-frame-pointer
              -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
              "-I${CMAKE_CURRENT_SOURCE_DIR}/include" "-I${ES_GENERATED_INCLUDE}" "-I${EIGEN3_INCLUDE_DIR}" ${map_fuzz_sources}
              -lz -o "${ES_MAP_FUZZER_BIN}"
      DEPENDS ${map_fuzz_sources} ${map_fuzz_headers}
      COMMENT "Building the map file reader's libFuzzer target with clang"
      VERBATIM)
    add_custom_target(map_file_fuzzer DEPENDS "${ES_MAP_FUZZER_BIN}")
    add_dependencies(map_file_fuzzer evidential_slam_build_info)
  endif()

  catkin_add_gtest(test_map_file_fuzz test/io/map_file_fuzz_test.cpp test/io/test_main.cpp)
  target_link_libraries(test_map_file_fuzz evidential_slam_io)
  target_compile_definitions(test_map_file_fuzz PRIVATE ${MAP_FILE_TEST_DEFINITIONS}
    ES_FUZZER_BIN="${ES_MAP_FUZZER_BIN}"
    ES_ALLOW_NO_FUZZER=$<BOOL:${ES_ALLOW_NO_FUZZER}>)
  if(ES_MAP_FUZZER_BIN)
    add_dependencies(test_map_file_fuzz map_file_fuzzer)
  endif()
endif()
