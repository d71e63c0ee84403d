# The build tree's data folder, build/share/backlash, laid out as an installation's
# PREFIX/share/backlash (model/data_dir.hpp) but made of symbolic links into the source
# tree, so an edit of cases/V.toml is seen at once, as before:
#   cases/   → cases/
#   errata/  → reports/errata/
#   data/    → reports/data/*.toml and tests/numeric/data/thesis_dividing_line_tables.toml
# The installed copies: cmake/BacklashPackaging.cmake.
set(BACKLASH_BUILD_DATA_DIR ${CMAKE_BINARY_DIR}/share/backlash CACHE INTERNAL "the build tree's share/backlash")
set(BACKLASH_DATA_FILES
  ${CMAKE_SOURCE_DIR}/reports/data/thesis_cases.toml
  ${CMAKE_SOURCE_DIR}/reports/data/thesis_figures.toml
  ${CMAKE_SOURCE_DIR}/reports/data/thesis_step_tables.toml
  ${CMAKE_SOURCE_DIR}/tests/numeric/data/thesis_dividing_line_tables.toml
  CACHE INTERNAL "the files of share/backlash/data")

file(MAKE_DIRECTORY ${BACKLASH_BUILD_DATA_DIR}/data)
function(backlash_link_into_build_data source link)
  if(IS_SYMLINK ${link} OR EXISTS ${link})
    file(REMOVE ${link})
  endif()
  file(CREATE_LINK ${source} ${link} SYMBOLIC)
endfunction()
backlash_link_into_build_data(${CMAKE_SOURCE_DIR}/cases ${BACKLASH_BUILD_DATA_DIR}/cases)
backlash_link_into_build_data(${CMAKE_SOURCE_DIR}/reports/errata ${BACKLASH_BUILD_DATA_DIR}/errata)
foreach(file IN LISTS BACKLASH_DATA_FILES)
  get_filename_component(name ${file} NAME)
  backlash_link_into_build_data(${file} ${BACKLASH_BUILD_DATA_DIR}/data/${name})
endforeach()
