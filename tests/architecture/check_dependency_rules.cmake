# check_dependency_rules — which library may link which (docs/design.md, "Library and package"),
# read from the link closures the configuration writes (cmake/BacklashLinkRules.cmake:
# backlash_write_link_closures → build/link_closures/<target>.txt, libraries.txt).
#
#   cmake -DCLOSURES=build/link_closures -P check_dependency_rules.cmake
#
# Fails (one line per broken rule) when
#   - backlash_output links any library of ours (it is the bottom layer), or backlash_model links
#     any but backlash_output;
#   - backlash_numeric links the facade, the map, the report layer, discrepancy or GiNaC;
#   - backlash_api or backlash_api_derive links the report layer (backlash_reports, backlash_plot,
#     backlash_discrepancy_pages) or the map, or backlash_api GiNaC;
#   - the map (backlash_map, backlash_map_figures, backlash_map_mpi) links backlash_reports or GiNaC
#     (backlash_plot, the GiNaC-free gnuplot figures, is allowed);
#   - backlash_measurements or backlash_discrepancy links GiNaC;
#   - any other library links GiNaC: GiNaC (PkgConfig::GINAC, backlash_symbolic,
#     backlash_codegen_lib) is allowed only in symbolic/, codegen/, backlash_api_derive and the
#     report layer (backlash_reports).
# A rule naming a library the build does not have is skipped (e.g. backlash_map_mpi without MPI).
cmake_minimum_required(VERSION 3.25)
if(NOT CLOSURES OR NOT EXISTS "${CLOSURES}/libraries.txt")
  message(FATAL_ERROR "check_dependency_rules: no link closures at '${CLOSURES}' (give -DCLOSURES=build/link_closures)")
endif()

set(ginac PkgConfig::GINAC backlash_symbolic backlash_codegen_lib)
set(reports_layer backlash_reports backlash_plot backlash_discrepancy_pages)
set(map_layer backlash_map backlash_map_figures backlash_map_mpi)
set(ginac_allowed backlash_symbolic backlash_codegen_lib backlash_api_derive backlash_reports)

set(broken 0)
file(STRINGS "${CLOSURES}/libraries.txt" libraries)

# closure_of(library variable): the libraries it links, itself left out.
function(closure_of library variable)
  file(STRINGS "${CLOSURES}/${library}.txt" closure)
  list(REMOVE_ITEM closure ${library})
  set(${variable} ${closure} PARENT_SCOPE)
endfunction()

# forbid(library why name...): each name in the closure of `library` breaks the rule `why`;
# any entry naming GiNaC or CLN counts as PkgConfig::GINAC.
function(forbid library why)
  if(NOT library IN_LIST libraries)
    return()
  endif()
  closure_of(${library} closure)
  foreach(entry IN LISTS closure)
    set(name ${entry})
    string(TOLOWER "${entry}" lower)
    if(lower MATCHES "ginac|(^|[^a-z])(lib)?cln($|[^a-z.])")
      set(name PkgConfig::GINAC)
    endif()
    if(name IN_LIST ARGN)
      message(SEND_ERROR "check_dependency_rules: ${library} links ${entry} (${why})")
      set(broken 1 PARENT_SCOPE)
    endif()
  endforeach()
endfunction()

# backlash_output: nothing of ours; backlash_model: backlash_output only.
set(ours ${libraries})
list(REMOVE_ITEM ours backlash_output)
forbid(backlash_output "the output layer is the bottom layer: it links no library of backlash" ${ours})
list(REMOVE_ITEM ours backlash_model)
forbid(backlash_model "the model sits on the output layer alone: it links no other library of backlash" ${ours})
forbid(backlash_numeric "numeric is below the facade, the map, the report and discrepancy, and never GiNaC"
  backlash_api backlash_api_derive ${map_layer} ${reports_layer} backlash_discrepancy ${ginac})
forbid(backlash_api "the facade links neither the report layer nor the map (which are built on it) nor GiNaC"
  ${reports_layer} ${map_layer} ${ginac})
forbid(backlash_api_derive "the GiNaC facade links neither the report layer nor the map (which are built on it)"
  ${reports_layer} ${map_layer})
foreach(map_library IN LISTS map_layer)
  forbid(${map_library} "the map may draw with backlash_plot but links neither the report nor GiNaC"
    backlash_reports ${ginac})
endforeach()
forbid(backlash_measurements "measurements never link GiNaC" ${ginac})
forbid(backlash_discrepancy "discrepancy never links GiNaC" ${ginac})
foreach(library IN LISTS libraries)
  if(NOT library IN_LIST ginac_allowed AND NOT library MATCHES "^backlash_(symbolic|codegen)")
    forbid(${library} "GiNaC only in symbolic/, codegen/, backlash_api_derive and the report layer" ${ginac})
  endif()
endforeach()

if(broken)
  message(FATAL_ERROR "check_dependency_rules: the dependency rules are broken (above)")
endif()
list(LENGTH libraries count)
message(STATUS "check_dependency_rules: ${count} libraries, every rule holds")
