# OctoMap export: the evidential_slam_octomap library (EvidentialOcTree, the export of a grid to
# .evidential.ot / .bt / .color.ot, the checked reader), the evidential_octomap_info tool, the
# offline runner's --export-octomap.
# Included from CMakeLists.txt right after the offline runner's target. evidential_slam_io (the
# src/io/*.cpp glob) stays free of OctoMap: everything OctoMap lives in src/io/octomap/.

find_package(octomap REQUIRED)  # 1.9: imported targets octomap, octomath

file(GLOB OCTOMAP_IO_SOURCES CONFIGURE_DEPENDS src/io/octomap/*.cpp)
add_library(evidential_slam_octomap ${OCTOMAP_IO_SOURCES})
target_include_directories(evidential_slam_octomap PUBLIC include)
target_link_libraries(evidential_slam_octomap PUBLIC evidential_slam_io octomap octomath)
set_target_properties(evidential_slam_octomap PROPERTIES POSITION_INDEPENDENT_CODE ON)

# --export-octomap (offline_main.cpp passes exportOctomapForOfflineRun to the runner).
target_link_libraries(evidential_slam_offline evidential_slam_octomap)

add_executable(evidential_octomap_info src/apps/evidential_octomap_info.cpp)
target_link_libraries(evidential_octomap_info evidential_slam_octomap)

install(TARGETS evidential_slam_octomap
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_GLOBAL_BIN_DESTINATION})
install(TARGETS evidential_octomap_info RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
