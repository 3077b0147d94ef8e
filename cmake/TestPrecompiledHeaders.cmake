# Precompiled headers for the test programs. Parsing GoogleTest, Eigen and (for the tests on the
# ros room) roscpp is most of a test file's compile time, and the same for every file
# (docs/development.md#build-times). Two headers are built once each, in targets of their own
# that define nothing beyond this directory's definitions: GCC uses a precompiled header only where
# every macro defined when it was built is defined alike, and the test programs each define
# their own paths (ES_TEST_DATA_DIR, ...), which the headers never read.
# Called at the end of the tests section: every executable of this directory that links
# GoogleTest is a test program.
function(es_test_precompiled_headers)
  set(empty "${PROJECT_BINARY_DIR}/test_pch/empty.cpp")
  file(WRITE "${empty}" "")
  set(headers <gtest/gtest.h> <Eigen/Core> <Eigen/Geometry>
    <algorithm> <cmath> <map> <memory> <random> <string> <vector>)
  add_library(es_test_pch_plain OBJECT EXCLUDE_FROM_ALL "${empty}")
  target_link_libraries(es_test_pch_plain PRIVATE ${GTEST_LIBRARIES} Eigen3::Eigen)
  target_precompile_headers(es_test_pch_plain PRIVATE ${headers})
  add_library(es_test_pch_ros OBJECT EXCLUDE_FROM_ALL "${empty}")
  target_include_directories(es_test_pch_ros PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(es_test_pch_ros PRIVATE ${GTEST_LIBRARIES} Eigen3::Eigen)
  target_precompile_headers(es_test_pch_ros PRIVATE ${headers} <ros/ros.h>)

  get_property(targets DIRECTORY "${PROJECT_SOURCE_DIR}" PROPERTY BUILDSYSTEM_TARGETS)
  foreach(t ${targets})
    get_target_property(type ${t} TYPE)
    get_target_property(libs ${t} LINK_LIBRARIES)
    if(NOT type STREQUAL "EXECUTABLE" OR NOT "${libs}" MATCHES "gtest")
      continue()
    endif()
    if("${libs}" MATCHES "evidential_slam_ros")
      target_precompile_headers(${t} REUSE_FROM es_test_pch_ros)
    else()
      target_precompile_headers(${t} REUSE_FROM es_test_pch_plain)
    endif()
  endforeach()
endfunction()
