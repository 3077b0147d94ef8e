# The libFuzzer targets of test/fuzz/ (rawlog, ground truth, waypoints, parameter files, layer
# folders) and their smoke test.
# Included from CMakeLists.txt in the tests section, after cmake/OctomapTargets.cmake, whose probe
# sets ES_FUZZER_BIN when clang can link -fsanitize=fuzzer. test/fuzz/ is a project of its own
# (the package builds with gcc) configured and built with that clang by ExternalProject when the
# smoke test is built; without clang the smoke test fails, or skips with -DES_ALLOW_NO_FUZZER=ON.

include(ExternalProject)

set(ES_FUZZ_DIR "${CMAKE_CURRENT_BINARY_DIR}/fuzzers")
set(ES_FUZZ_NAMES rawlog_fuzzer ground_truth_fuzzer waypoints_fuzzer yaml_config_fuzzer
  layers_fuzzer)
set(ES_FUZZ_BINS "")
if(ES_FUZZER_BIN)
  foreach(name ${ES_FUZZ_NAMES})
    list(APPEND ES_FUZZ_BINS "${ES_FUZZ_DIR}/${name}")
  endforeach()
  ExternalProject_Add(es_fuzzers
    SOURCE_DIR "${CMAKE_CURRENT_SOURCE_DIR}/test/fuzz"
    BINARY_DIR "${ES_FUZZ_DIR}"
    CMAKE_ARGS -DCMAKE_CXX_COMPILER=${ES_CLANGXX} -DES_REPO=${CMAKE_CURRENT_SOURCE_DIR}
               -DES_GENERATED_INCLUDE=${ES_GENERATED_INCLUDE}
               -DCMAKE_BUILD_TYPE=
    INSTALL_COMMAND ""
    BUILD_ALWAYS ON
    EXCLUDE_FROM_ALL ON
    BUILD_BYPRODUCTS ${ES_FUZZ_BINS})
endif()

catkin_add_gtest(test_fuzz_smoke test/fuzz/fuzz_smoke_test.cpp test/io/test_main.cpp)
target_include_directories(test_fuzz_smoke PRIVATE test/io)
target_compile_definitions(test_fuzz_smoke PRIVATE
  ES_FUZZ_DIR="$<$<BOOL:${ES_FUZZER_BIN}>:${ES_FUZZ_DIR}>"
  ES_FUZZ_CORPUS_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/fuzz/corpus"
  ES_TEST_DATA_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/data"
  ES_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}/test_tmp"
  ES_ALLOW_NO_FUZZER=$<BOOL:${ES_ALLOW_NO_FUZZER}>)
if(ES_FUZZER_BIN)
  add_dependencies(test_fuzz_smoke es_fuzzers)
  add_dependencies(es_fuzzers evidential_slam_parameter_fields)
endif()
