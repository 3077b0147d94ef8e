# OctoMap export, around the evidential_slam_octomap library (src/io/octomap/CMakeLists.txt): the
# evidential_octomap_info tool, the tests of the export behind export_octomap
# (session/map_files.cpp) and the reader's libFuzzer target.

add_executable(evidential_octomap_info src/apps/evidential_octomap_info.cpp)
target_link_libraries(evidential_octomap_info evidential_slam_octomap)

install(TARGETS evidential_octomap_info RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # octomap-tools' own programs read the exported .bt in a test.
  find_program(ES_BT2VRML bt2vrml)
  find_program(ES_CONVERT_OCTREE convert_octree)
  find_program(ES_COMPARE_OCTREES compare_octrees)
  foreach(tool ES_BT2VRML ES_CONVERT_OCTREE ES_COMPARE_OCTREES)
    if(NOT ${tool})
      message(WARNING "${tool}: not found (install octomap-tools); its test will fail")
      set(${tool} "")
    endif()
  endforeach()

  # A program that knows the tree only through OctoMap's factory (AbstractOcTree::read and a
  # dynamic_cast), as a third party would: proves --as-needed keeps the library and its
  # registration (build-notes.md item 5).
  add_executable(evidential_octomap_consumer test/io/octomap_factory_consumer.cpp)
  target_link_libraries(evidential_octomap_consumer evidential_slam_octomap)

  set(OCTOMAP_TEST_DEFINITIONS
    ES_TEST_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/data"
    ES_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}/test_tmp"
    ES_OFFLINE_BIN="$<TARGET_FILE:evidential_slam_offline>"
    ES_INFO_BIN="$<TARGET_FILE:evidential_octomap_info>"
    ES_CONSUMER_BIN="$<TARGET_FILE:evidential_octomap_consumer>"
    ES_BT2VRML="${ES_BT2VRML}"
    ES_CONVERT_OCTREE="${ES_CONVERT_OCTREE}"
    ES_COMPARE_OCTREES="${ES_COMPARE_OCTREES}")

  catkin_add_gtest(test_octomap
    test/io/octomap_tree_test.cpp test/io/octomap_tools_test.cpp test/io/test_main.cpp)
  target_link_libraries(test_octomap evidential_slam_octomap nlohmann_json::nlohmann_json)
  target_compile_definitions(test_octomap PRIVATE ${OCTOMAP_TEST_DEFINITIONS})
  add_dependencies(test_octomap evidential_slam_offline evidential_octomap_info
    evidential_octomap_consumer)

  # --- libFuzzer target for the reader -------------------------------------------------------
  # Built with clang (the package itself builds with gcc) when clang++ can link -fsanitize=fuzzer
  # (Debian: clang + libclang-rt-14-dev, both in scripts/packages.txt). test_octomap_fuzz runs it
  # for a few seconds on a seed corpus it writes; without a usable clang that test FAILS and says
  # why (configure with -DES_ALLOW_NO_FUZZER=ON to turn it into a reported skip instead).
  option(ES_ALLOW_NO_FUZZER "Skip (instead of fail) the fuzz test when clang/libFuzzer is missing"
    OFF)
  set(ES_FUZZER_BIN "")
  # Off in scripts/test's sanitizer workspaces: the fuzz targets are ASan builds of their own.
  option(ES_BUILD_FUZZERS "Build the clang libFuzzer targets" ON)
  find_program(ES_CLANGXX NAMES clang++ clang++-14)
  if(ES_CLANGXX AND NOT ES_BUILD_FUZZERS)
    message(STATUS "ES_BUILD_FUZZERS is off: no libFuzzer targets")
  elseif(ES_CLANGXX)
    set(probe_dir "${CMAKE_CURRENT_BINARY_DIR}/fuzzer_probe")
    file(WRITE "${probe_dir}/probe.cpp"
      "#include <cstddef>\n#include <cstdint>\n"
      "extern \"C\" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }\n")
    execute_process(
      COMMAND "${ES_CLANGXX}" -fsanitize=fuzzer,address,undefined "${probe_dir}/probe.cpp"
              -o "${probe_dir}/probe"
      RESULT_VARIABLE probe_rc OUTPUT_QUIET ERROR_VARIABLE probe_err)
    if(probe_rc EQUAL 0)
      set(ES_FUZZER_BIN "${CMAKE_CURRENT_BINARY_DIR}/evidential_octree_fuzzer")
    else()
      message(WARNING "${ES_CLANGXX} cannot link -fsanitize=fuzzer (install libclang-rt-14-dev): "
        "${probe_err}")
    endif()
  else()
    message(WARNING "clang++ not found: the reader's fuzz test will fail (install clang)")
  endif()

  if(ES_FUZZER_BIN)
    set(fuzz_sources
      "${CMAKE_CURRENT_SOURCE_DIR}/test/io/octomap_reader_fuzzer.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/io/octomap/evidential_octree.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/core/mass.cpp"
      "${CMAKE_CURRENT_SOURCE_DIR}/src/core/measures.cpp")
    file(GLOB fuzz_headers CONFIGURE_DEPENDS
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/io/evidential_octree.h"
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/core/mass.h"
      "${CMAKE_CURRENT_SOURCE_DIR}/include/evidential_slam/core/measures.h")
    add_custom_command(OUTPUT "${ES_FUZZER_BIN}"
      COMMAND "${ES_CLANGXX}" -std=c++17 -O1 -g -fno-omit-frame-pointer
              -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
              "-I${CMAKE_CURRENT_SOURCE_DIR}/include" "-I${ES_GENERATED_INCLUDE}" "-I${EIGEN3_INCLUDE_DIR}" ${fuzz_sources}
              "$<TARGET_FILE:octomap>" "$<TARGET_FILE:octomath>" -o "${ES_FUZZER_BIN}"
      DEPENDS ${fuzz_sources} ${fuzz_headers}
      COMMENT "Building the EvidentialOcTree reader's libFuzzer target with clang"
      VERBATIM)
    add_custom_target(evidential_octree_fuzzer DEPENDS "${ES_FUZZER_BIN}")
  endif()

  catkin_add_gtest(test_octomap_fuzz test/io/octomap_fuzz_test.cpp test/io/test_main.cpp)
  target_link_libraries(test_octomap_fuzz evidential_slam_octomap)
  target_compile_definitions(test_octomap_fuzz PRIVATE ${OCTOMAP_TEST_DEFINITIONS}
    ES_FUZZER_BIN="${ES_FUZZER_BIN}"
    ES_ALLOW_NO_FUZZER=$<BOOL:${ES_ALLOW_NO_FUZZER}>)
  if(ES_FUZZER_BIN)
    add_dependencies(test_octomap_fuzz evidential_octree_fuzzer)
  endif()
endif()
