# exam_installed_package — the build installed into a fresh prefix, then used as someone
# else would use it, from another folder, with no BACKLASH_* variable set:
#   1. `cmake --install` lays out bin/, include/, lib/, lib/cmake/backlash, share/backlash;
#   2. the installed CLI works from a folder outside both trees (a thesis case, and a case
#      file given by a relative path) and prints what the build tree's prints; no source or
#      build path is compiled into the installed binaries and libraries, nor written into
#      the CMake package files;
#   3. tests/package/consumer (find_package(backlash), case V's limit cycle through the
#      facade and through backlash::numeric alone, a map's sensitivity ranking through
#      backlash::map_figures alone, a map's points through backlash::map) configures, builds
#      and runs — without GiNaC mapped;
#   4. the README's C++ example, taken from README.md itself, builds and prints the
#      output the README shows;
#   5. the installed Python module imports and finds its data beside the prefix; the
#      issue's command `python3 -c "import backlash; print(backlash.load('V').limit_cycle())"`
#      prints what `backlash limit-cycle V` prints.
# Arguments (-D): BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR CXX CHECK_PATHS [PYTHON PYTHON_DIR]
# [EXTRA_FLAGS: compiler and linker flags for the consumers, e.g. a sanitizer build's]
cmake_minimum_required(VERSION 3.25)

function(fail)
  string(JOIN "" message ${ARGN})
  message(FATAL_ERROR "exam_installed_package: ${message}")
endfunction()

# Runs a command (BACKLASH_* unset) in WORK_DIR (or in the folder RUN_IN names); fails
# unless it exits 0; stdout → out_var.
function(run out_var)
  if(NOT RUN_IN)
    set(RUN_IN ${WORK_DIR})
  endif()
  set(sanitizer_defaults)
  if(EXTRA_FLAGS AND NOT DEFINED ENV{ASAN_OPTIONS})  # as cmake/sanitizer_defaults.cpp for our own programs
    set(sanitizer_defaults ASAN_OPTIONS=detect_leaks=0)
  endif()
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env --unset=BACKLASH_CASES_DIR --unset=BACKLASH_DATA_DIR ${sanitizer_defaults} ${ARGN}
    WORKING_DIRECTORY ${RUN_IN}
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    string(JOIN " " command ${ARGN})
    fail("`${command}` returned ${status} instead of 0:\n${out}\n${err}")
  endif()
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
set(consumer_arguments -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix})
if(EXTRA_FLAGS)
  list(APPEND consumer_arguments "-DCMAKE_CXX_FLAGS=${EXTRA_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${EXTRA_FLAGS}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

# 1. install
run(ignored ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(file
    bin/backlash
    include/backlash/api/backlash.hpp include/backlash/api/derive.hpp include/backlash/model/case_spec.hpp
    include/backlash/numeric/limit_cycle.hpp include/backlash/generated/case_V.hpp
    include/backlash/map/map.hpp include/backlash/map/figures.hpp include/backlash/api/map.hpp
    include/backlash/reports/plot.hpp
    lib/cmake/backlash/backlashConfig.cmake lib/cmake/backlash/backlashConfigVersion.cmake
    lib/cmake/backlash/backlashTargets.cmake
    share/backlash/cases/V.toml share/backlash/errata/ledger.toml share/backlash/data/thesis_cases.toml
    share/backlash/data/thesis_dividing_line_tables.toml share/doc/backlash/README.md share/doc/backlash/design.md)
  if(NOT EXISTS ${prefix}/${file})
    fail("cmake --install did not install ${file}")
  endif()
endforeach()
file(GLOB libraries ${prefix}/lib/libbacklash_api.* ${prefix}/lib/libbacklash_numeric.*)
list(LENGTH libraries count)
if(count LESS 2)
  fail("cmake --install installed ${count} of the libraries libbacklash_api, libbacklash_numeric instead of both")
endif()

# 2. the installed CLI, from a folder outside the source and build trees
string(RANDOM LENGTH 8 suffix)
set(elsewhere /tmp/backlash-package-${suffix})
file(MAKE_DIRECTORY ${elsewhere})
file(COPY_FILE ${SOURCE_DIR}/cases/V.toml ${elsewhere}/mine.toml)
set(RUN_IN ${elsewhere})
run(installed ${prefix}/bin/backlash limit-cycle V --json)
run(installed_text ${prefix}/bin/backlash limit-cycle V)
run(installed_file ${prefix}/bin/backlash limit-cycle mine.toml --json)
unset(RUN_IN)
run(built ${BUILD_DIR}/bin/backlash limit-cycle V --json)
run(built_file ${BUILD_DIR}/bin/backlash limit-cycle ${elsewhere}/mine.toml --json)
file(REMOVE_RECURSE ${elsewhere})
if(NOT installed STREQUAL built)
  fail("the installed `backlash limit-cycle V --json` returned\n${installed}\ninstead of\n${built}")
endif()
if(NOT installed_file STREQUAL built_file)
  fail("the installed `backlash limit-cycle mine.toml --json` (a copy of V.toml) returned\n${installed_file}\n"
       "instead of what the build tree's CLI prints for it:\n${built_file}")
endif()
file(GLOB modules ${prefix}/${PYTHON_DIR}/backlash/*.so)
file(GLOB libraries ${prefix}/lib/libbacklash_*)
file(GLOB package_files ${prefix}/lib/cmake/backlash/*.cmake)
foreach(file ${package_files})  # the package files: relative to the prefix, whatever the build type
  file(READ ${file} text)
  foreach(path ${SOURCE_DIR} ${BUILD_DIR})
    string(FIND "${text}" "${path}" at)
    if(NOT at EQUAL -1)
      fail("${file} contains the path ${path} instead of paths relative to the installed prefix")
    endif()
  endforeach()
endforeach()
if(CHECK_PATHS)
  foreach(binary ${prefix}/bin/backlash ${modules} ${libraries})
    foreach(path ${SOURCE_DIR} ${BUILD_DIR})
      file(STRINGS ${binary} found LIMIT_COUNT 1 REGEX "${path}")
      if(found)
        fail("${binary} contains the path ${path} (\"${found}\") instead of finding its data at run time")
      endif()
    endforeach()
  endforeach()
endif()

# 3. a consumer project
run(ignored ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package/consumer -B ${WORK_DIR}/consumer ${consumer_arguments})
run(ignored ${CMAKE_COMMAND} --build ${WORK_DIR}/consumer)
run(consumer ${WORK_DIR}/consumer/consumer)
file(REAL_PATH ${prefix}/share/backlash share)
set(expected "V limit_cycle 0.500728496422\ndata: ${share}\nginac mapped: no\n")
if(NOT consumer STREQUAL expected)
  fail("the consumer printed\n${consumer}\ninstead of\n${expected}")
endif()
run(numeric_only ${WORK_DIR}/consumer/numeric_only)
if(NOT numeric_only STREQUAL "V 0.500728496422\nginac mapped: no\n")
  fail("the numeric-only consumer printed\n${numeric_only}\ninstead of\nV 0.500728496422\nginac mapped: no")
endif()

# swings 0, 0 at K = 1 and 0.01, 0.03 at K = 2: the variance of the bin means over the
# total variance is 2/3 for K (bin means 0, 0.02) and 1/6 for backlash (0.005, 0.015)
run(map_figures_only ${WORK_DIR}/consumer/map_figures_only)
if(NOT map_figures_only STREQUAL "K 0.6667\nbacklash 0.1667\nginac mapped: no\n")
  fail("the map-figures consumer printed\n${map_figures_only}\ninstead of\nK 0.6667\nbacklash 0.1667\nginac mapped: no")
endif()

# a grid of 2 × 3 points over case V (backlash::map, through the facade's backlash/api/map.hpp)
run(map_only ${WORK_DIR}/consumer/map_only)
if(NOT map_only STREQUAL "6 points, x_K = 1.5, K 1.5\nginac mapped: no\n")
  fail("the map consumer printed\n${map_only}\ninstead of\n6 points, x_K = 1.5, K 1.5\nginac mapped: no")
endif()

# 4. the README's C++ example and the output the README shows for it
run(ignored ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package/readme -B ${WORK_DIR}/readme ${consumer_arguments}
    -DREADME=${SOURCE_DIR}/README.md)
run(ignored ${CMAKE_COMMAND} --build ${WORK_DIR}/readme)
run(printed ${WORK_DIR}/readme/readme)
file(READ ${SOURCE_DIR}/README.md readme)
string(FIND "${readme}" "<!-- example: readme.cpp output -->" marker)
if(marker EQUAL -1)
  fail("README.md: no '<!-- example: readme.cpp output -->' before the example's output")
endif()
string(SUBSTRING "${readme}" ${marker} -1 readme)
string(REGEX MATCH "```text\n(.*)" block "${readme}")
string(FIND "${CMAKE_MATCH_1}" "```" end)
string(SUBSTRING "${CMAKE_MATCH_1}" 0 ${end} shown)
if(NOT printed STREQUAL shown)
  fail("the README's C++ example printed\n${printed}\ninstead of what the README shows:\n${shown}")
endif()

# 5. the installed Python module.  The commands go through a shell script: CMake would cut
# the issue's command at its ';' (a list separator) if it were passed as an argument.
if(PYTHON AND EXISTS ${prefix}/${PYTHON_DIR}/backlash/__init__.py)
  file(MAKE_DIRECTORY ${elsewhere})
  set(python_environment "PYTHONPATH='${prefix}/${PYTHON_DIR}' PYTHONDONTWRITEBYTECODE=1")
  file(WRITE ${elsewhere}/data.sh
    "${python_environment} '${PYTHON}' -c \"import backlash; print(backlash.data_dir()); "
    "print('%.12f' % backlash.load('V').limit_cycle().peak_to_peak)\"\n")
  file(WRITE ${elsewhere}/issue.sh
    "${python_environment} '${PYTHON}' -c \"import backlash; print(backlash.load('V').limit_cycle())\"\n")
  set(RUN_IN ${elsewhere})
  run(python /bin/sh ${elsewhere}/data.sh)
  run(printed /bin/sh ${elsewhere}/issue.sh)  # the issue's command, from a folder outside both trees
  unset(RUN_IN)
  file(REMOVE_RECURSE ${elsewhere})
  file(REAL_PATH ${prefix}/share/backlash share)
  if(NOT python STREQUAL "${share}\n0.500728496422\n")
    fail("the installed Python module printed\n${python}\ninstead of\n${share}\n0.500728496422")
  endif()
  if(NOT printed STREQUAL installed_text)
    fail("python3 -c \"import backlash; print(backlash.load('V').limit_cycle())\" printed\n${printed}\n"
         "instead of what `backlash limit-cycle V` prints:\n${installed_text}")
  endif()
elseif(PYTHON)
  fail("cmake --install did not install the Python package into ${prefix}/${PYTHON_DIR}/backlash")
endif()
message(STATUS "exam_installed_package: installed into ${prefix}; CLI, consumer, README example and Python module pass")
