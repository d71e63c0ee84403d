// Figures and summary of a design-space map (reports/map_figures.hpp).  First version:
// the interface compiles and links; the figures follow.
#include "backlash/reports/map_figures.hpp"

#include <fstream>
#include <utility>

namespace backlash::reports {

struct MapFigures::Accumulators {};

MapFigures::MapFigures(std::string case_id, std::vector<MapAxis> axes, std::string sampling)
    : case_id_(std::move(case_id)), axes_(std::move(axes)), sampling_(std::move(sampling)) {}

void MapFigures::add(const MapPoint& point) {
  (void)point;
  ++points_;
}

void MapFigures::add_boundary(const MapBoundaryPoint& point) { boundary_.push_back(point); }

std::vector<MapSensitivity> MapFigures::sensitivities() const {
  std::vector<MapSensitivity> out;
  for (const MapAxis& axis : axes_) out.push_back({axis.name, 0.0});
  return out;
}

std::string MapFigures::summary_markdown() const { return "# Design-space map: case " + case_id_ + "\n"; }

std::string MapFigures::write(const std::filesystem::path& directory) const {
  std::ofstream(directory / "summary.md", std::ios::binary) << summary_markdown();
  return "figures not drawn yet";
}

}  // namespace backlash::reports
