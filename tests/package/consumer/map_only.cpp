// A design-space map's points with the installed backlash::map, through the facade's header
// (backlash/api/map.hpp): a 3 × 2 grid over case V, point 2's varied value and parameter —
// and whether GiNaC came along.
#include <backlash/api/map.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

int main() {
  namespace api = backlash::api;
  api::MapRequest r;
  r.target = "V";
  r.vary = {api::parse_vary("K=1:2:3"), api::parse_vary("backlash=0.1:0.2:2")};
  const api::MapPlan plan(r);
  std::printf("%ld points, x_K = %g, K %g\n", plan.count(), plan.values(2)[0], plan.point(2).parameters.K);
  std::ifstream maps("/proc/self/maps");
  std::stringstream text;
  text << maps.rdbuf();
  std::printf("ginac mapped: %s\n", text.str().find("libginac") == std::string::npos ? "no" : "yes");
  return 0;
}
