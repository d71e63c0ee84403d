# The package: what `cmake --install build --prefix P` puts where, and the files that let
# another CMake project use it (docs/design.md, "Library and package"):
#
#   P/bin/backlash                              the CLI
#   P/include/backlash/<part>/*.hpp             the headers (model numeric measurements
#                                               discrepancy symbolic codegen generated api map)
#   P/lib/libbacklash_<part>.a (.so with -DBACKLASH_SHARED=ON)
#   P/lib/cmake/backlash/backlashConfig.cmake, backlashConfigVersion.cmake, backlashTargets*.cmake
#                                               find_package(backlash) → backlash::model,
#                                               ::numeric, ::measurements, ::discrepancy,
#                                               ::symbolic, ::codegen, ::generated, ::api,
#                                               ::api_derive, ::map, ::map_figures (::map_mpi)
#   P/share/backlash/cases/*.toml               the thesis's cases  (model/data_dir.hpp: found
#   P/share/backlash/errata/*.toml              the errata ledger    at run time from the
#   P/share/backlash/data/*.toml                the thesis's numbers binary's own location)
#   P/share/doc/backlash/                       README.md, docs/*.md
#   P/<BACKLASH_PYTHON_INSTALL_DIR>/backlash/   the Python module (python/CMakeLists.txt)
#
# The libraries' own install rules are beside them (backlash_install_library in each
# CMakeLists.txt, cmake/BacklashInstall.cmake).
include(CMakePackageConfigHelpers)

set(BACKLASH_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/backlash)

install(TARGETS backlash RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

install(DIRECTORY ${CMAKE_SOURCE_DIR}/cases/ DESTINATION ${CMAKE_INSTALL_DATADIR}/backlash/cases
  FILES_MATCHING PATTERN "*.toml")
install(DIRECTORY ${CMAKE_SOURCE_DIR}/reports/errata/ DESTINATION ${CMAKE_INSTALL_DATADIR}/backlash/errata
  FILES_MATCHING PATTERN "*.toml")
install(FILES ${BACKLASH_DATA_FILES} DESTINATION ${CMAKE_INSTALL_DATADIR}/backlash/data)
install(FILES ${CMAKE_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} FILES_MATCHING PATTERN "*.md")

install(EXPORT backlashTargets
  NAMESPACE backlash::
  FILE backlashTargets.cmake
  DESTINATION ${BACKLASH_INSTALL_CMAKEDIR})

# Static libraries carry their private dependencies to the consumer's link line.
if(BACKLASH_SHARED)
  set(BACKLASH_PACKAGE_STATIC OFF)
else()
  set(BACKLASH_PACKAGE_STATIC ON)
endif()
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/backlashConfig.cmake.in
  ${CMAKE_BINARY_DIR}/package/backlashConfig.cmake
  INSTALL_DESTINATION ${BACKLASH_INSTALL_CMAKEDIR})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/package/backlashConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES
  ${CMAKE_BINARY_DIR}/package/backlashConfig.cmake
  ${CMAKE_BINARY_DIR}/package/backlashConfigVersion.cmake
  DESTINATION ${BACKLASH_INSTALL_CMAKEDIR})
