// A design-space map's summary with backlash::map_figures alone (no facade, no GiNaC):
// four points of a 2 × 2 grid, the ranking of the two parameters — and whether GiNaC came along.
#include <backlash/map/figures.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

int main() {
  namespace figures = backlash::map::figures;
  figures::MapFigures map("V", {{"K", 1, 2, 2}, {"backlash", 0.1, 0.3, 2}}, "grid");
  const double swing[2][2] = {{0.0, 0.0}, {0.01, 0.03}};  // [K][backlash]: K moves it most
  std::int64_t index = 0;
  for (int k = 0; k < 2; ++k)
    for (int b = 0; b < 2; ++b) {
      figures::MapPoint p;
      p.index = index++;
      p.x = {1.0 + k, 0.1 + 0.2 * b};
      p.status = swing[k][b] > 0 ? "limit_cycle" : "none";
      p.peak_to_peak = swing[k][b];
      map.add(p);
    }
  for (const figures::MapSensitivity& s : map.sensitivities()) std::printf("%s %.4f\n", s.name.c_str(), s.first_order_index);
  std::ifstream maps("/proc/self/maps");
  std::stringstream text;
  text << maps.rdbuf();
  std::printf("ginac mapped: %s\n", text.str().find("libginac") == std::string::npos ? "no" : "yes");
  return 0;
}
