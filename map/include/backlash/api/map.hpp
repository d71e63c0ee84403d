// backlash/api/map.hpp — design-space maps as the facade's users know them (the CLI's
// `backlash map`, the Python module, programs of one's own): the map library
// (backlash/map/map.hpp, target backlash::map) under the facade's namespace, backlash::api.
// The map is built on the facade (a case, BadInput, status_of), not inside it: link
// backlash::map for this header (backlash::api alone does not carry the map).
//
//   #include "backlash/api/map.hpp"                         // target backlash::map (no GiNaC)
//   backlash::api::MapRequest r;
//   r.target = "V";
//   r.vary = {backlash::api::parse_vary("JL_over_Jm=0.25:4:40"), backlash::api::parse_vary("FL_over_F=0:1:40")};
//   backlash::api::write_map(r, {.out = "map-V"});   // the files of `backlash map --out`
#pragma once

#include "backlash/map/map.hpp"

namespace backlash::api {

using map::MapAxis;
using map::parse_vary;
using map::MapRequest;
using map::MapPlan;
using map::MapRow;
using map::map_csv_header;
using map::map_csv_row;
using map::MapBoundaryRow;
using map::map_boundary_csv_header;
using map::map_boundary_csv_row;
using map::run_map;
using map::solve_boundary;
using map::MapTransport;
using map::MapOutput;
using map::MapSummary;
using map::write_map;
using map::map_partial_folder;

}  // namespace backlash::api
