# The rooms and their one-way doors (docs/development.md#rooms): core <- io <- session <- ros.
# Each room's library names only its own headers as include path; it sees another room's headers
# only through a library it links, so an include against the arrows fails to compile. The headers
# all live under include/evidential_slam/<room>/, so the build tree holds one include root per room,
# rooms/<room>/evidential_slam/<room>, a link to that folder. es_room also installs the library
# and the room's headers.
function(es_room target room)
  set(root "${PROJECT_BINARY_DIR}/rooms/${room}")
  file(MAKE_DIRECTORY "${root}/evidential_slam")
  file(CREATE_LINK "${PROJECT_SOURCE_DIR}/include/evidential_slam/${room}"
    "${root}/evidential_slam/${room}" SYMBOLIC)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${root}> $<INSTALL_INTERFACE:${CATKIN_GLOBAL_INCLUDE_DESTINATION}>)
  # What the room compiles with, for the rooms test (test/rooms/check_rooms.py): its include
  # paths, own and inherited, one per line.
  file(GENERATE OUTPUT "${PROJECT_BINARY_DIR}/rooms/${room}.includes"
    CONTENT "$<JOIN:$<TARGET_PROPERTY:${target},INCLUDE_DIRECTORIES>,\n>\n")
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  install(TARGETS ${target}
    ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    RUNTIME DESTINATION ${CATKIN_GLOBAL_BIN_DESTINATION})
  install(DIRECTORY "${PROJECT_SOURCE_DIR}/include/evidential_slam/${room}/"
    DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION}/${room})
endfunction()
