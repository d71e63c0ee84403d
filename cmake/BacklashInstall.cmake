# Install and export helpers (the package: docs/design.md, "Library and package").
#
# backlash_install_library(target EXPORT_NAME name [HEADERS dir...])
#   Makes a library of this build part of the installed package:
#   - the alias backlash::<name>, so the build tree uses the names a consumer of the
#     installed package uses (find_package(backlash) → backlash::<name>);
#   - position-independent code (the Python module and shared builds link it);
#   - its include folders as $<BUILD_INTERFACE:...> plus $<INSTALL_INTERFACE:include>
#     (the paths into the source or build tree are never exported);
#   - install(TARGETS) into the export set backlashTargets, and the headers under
#     each HEADERS folder (*.hpp, the folder's layout kept) into include/.
include(GNUInstallDirs)

function(backlash_install_library target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "EXPORT_NAME" "HEADERS")
  if(NOT ARG_EXPORT_NAME)
    message(FATAL_ERROR "backlash_install_library(${target}): EXPORT_NAME is required")
  endif()
  add_library(backlash::${ARG_EXPORT_NAME} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_EXPORT_NAME})
  get_target_property(type ${target} TYPE)
  if(NOT type STREQUAL "INTERFACE_LIBRARY")
    set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()

  get_target_property(directories ${target} INTERFACE_INCLUDE_DIRECTORIES)
  set(exported_directories)
  if(directories)
    foreach(directory IN LISTS directories)
      if(directory MATCHES "^\\$<")
        list(APPEND exported_directories "${directory}")
      else()
        list(APPEND exported_directories "$<BUILD_INTERFACE:${directory}>")
      endif()
    endforeach()
  endif()
  list(APPEND exported_directories "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${exported_directories}")

  install(TARGETS ${target} EXPORT backlashTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  foreach(directory IN LISTS ARG_HEADERS)
    if(NOT IS_ABSOLUTE "${directory}")
      set(directory "${CMAKE_CURRENT_SOURCE_DIR}/${directory}")
    endif()
    install(DIRECTORY "${directory}" DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
      FILES_MATCHING PATTERN "*.hpp")
  endforeach()
endfunction()
