# backlash_forbid_links(TARGET target FORBIDDEN name... [REPORT file])
#
# Fails configuration when the transitive link closure of TARGET contains any
# of the FORBIDDEN targets/libraries (e.g. numeric/ must never link GiNaC).
# Call it deferred (cmake_language(DEFER DIRECTORY ${CMAKE_SOURCE_DIR} ...)) so
# that every target is defined when the closure is walked.  The closure is
# written to REPORT (one entry per line) for the tests to inspect.
include_guard(GLOBAL)

function(backlash_link_closure target out_var)
  set(seen "")
  set(queue ${target})
  while(queue)
    list(POP_FRONT queue item)
    # strip generator expressions such as $<LINK_ONLY:x> and $<BUILD_INTERFACE:x>
    string(REGEX REPLACE "^\\$<[A-Z_]+:(.*)>$" "\\1" item "${item}")
    if(item STREQUAL "" OR item IN_LIST seen)
      continue()
    endif()
    list(APPEND seen ${item})
    if(TARGET ${item})
      get_target_property(aliased ${item} ALIASED_TARGET)
      if(aliased)
        list(APPEND queue ${aliased})
      endif()
      get_target_property(type ${item} TYPE)
      set(links "")
      if(NOT type STREQUAL "INTERFACE_LIBRARY")
        get_target_property(direct ${item} LINK_LIBRARIES)
        if(direct)
          list(APPEND links ${direct})
        endif()
      endif()
      get_target_property(interface ${item} INTERFACE_LINK_LIBRARIES)
      if(interface)
        list(APPEND links ${interface})
      endif()
      list(APPEND queue ${links})
    endif()
  endwhile()
  set(${out_var} ${seen} PARENT_SCOPE)
endfunction()

function(backlash_forbid_links)
  cmake_parse_arguments(PARSE_ARGV 0 RULE "" "TARGET;REPORT" "FORBIDDEN")
  backlash_link_closure(${RULE_TARGET} closure)
  if(RULE_REPORT)
    string(REPLACE ";" "\n" lines "${closure}")
    file(WRITE ${RULE_REPORT} "${lines}\n")
  endif()
  foreach(forbidden IN LISTS RULE_FORBIDDEN)
    foreach(entry IN LISTS closure)
      string(TOLOWER "${entry}" lower_entry)
      string(TOLOWER "${forbidden}" lower_forbidden)
      if(lower_entry STREQUAL lower_forbidden OR lower_entry MATCHES "ginac")
        message(FATAL_ERROR
          "backlash: ${RULE_TARGET} must never link ${forbidden}, but its link closure contains '${entry}' "
          "(closure: ${closure}).  numeric/ may use Eigen, Boost.Odeint and Boost.Math only.")
      endif()
    endforeach()
  endforeach()
endfunction()

# backlash_write_link_closures(directory)
#
# Writes, for every library target of the project outside tests/ (static, shared, object or
# interface; not the Python extension modules), its link closure to directory/<target>.txt,
# one entry a line: the target itself first, then every target and library it links,
# directly or not, aliases (backlash::x) replaced by the targets they name.  directory/
# libraries.txt lists the targets.  Called deferred from the top-level CMakeLists.txt, once
# every target exists; tests/architecture/check_dependency_rules.cmake reads the files and
# fails on a link the rules forbid.
# backlash_collect_targets(directory TYPES regex [SKIP folder] result): the targets of
# `directory` and its subdirectories whose TYPE matches `regex`, leaving out `folder`'s.
function(backlash_collect_targets directory)
  cmake_parse_arguments(PARSE_ARGV 1 COLLECT "" "TYPES;SKIP" "")
  list(GET COLLECT_UNPARSED_ARGUMENTS 0 result_variable)
  get_property(targets DIRECTORY ${directory} PROPERTY BUILDSYSTEM_TARGETS)
  set(found)
  foreach(target IN LISTS targets)
    get_target_property(type ${target} TYPE)
    if(type MATCHES "${COLLECT_TYPES}")
      list(APPEND found ${target})
    endif()
  endforeach()
  get_property(subdirectories DIRECTORY ${directory} PROPERTY SUBDIRECTORIES)
  foreach(subdirectory IN LISTS subdirectories)
    if(NOT subdirectory STREQUAL "${COLLECT_SKIP}")
      backlash_collect_targets(${subdirectory} TYPES "${COLLECT_TYPES}" SKIP "${COLLECT_SKIP}" nested)
      list(APPEND found ${nested})
    endif()
  endforeach()
  set(${result_variable} ${found} PARENT_SCOPE)
endfunction()

function(backlash_write_link_closures directory)
  backlash_collect_targets(${CMAKE_SOURCE_DIR} TYPES "^(STATIC|SHARED|OBJECT|INTERFACE)_LIBRARY$"
                           SKIP "${CMAKE_SOURCE_DIR}/tests" libraries)
  file(REMOVE_RECURSE ${directory})
  foreach(library IN LISTS libraries)
    backlash_link_closure(${library} closure)
    set(resolved)
    foreach(entry IN LISTS closure)
      if(TARGET ${entry})
        get_target_property(aliased ${entry} ALIASED_TARGET)
        if(aliased)
          set(entry ${aliased})
        endif()
      endif()
      list(APPEND resolved ${entry})
    endforeach()
    list(REMOVE_DUPLICATES resolved)
    string(REPLACE ";" "\n" lines "${resolved}")
    file(WRITE ${directory}/${library}.txt "${lines}\n")
  endforeach()
  string(REPLACE ";" "\n" lines "${libraries}")
  file(WRITE ${directory}/libraries.txt "${lines}\n")
endfunction()
