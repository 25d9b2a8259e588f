#pragma once
// The kidnapped-robot figure: the map's scan positions (grey), and for every start its true path
// until the first fix (blue), the start (black), the first fix where the localizer put the robot
// (green when correct) and every wrong fix (red).

#include <string>
#include <vector>

#include <Eigen/Core>

namespace keyplace::cli {

struct StartDrawing {
  std::vector<Eigen::Vector2d> path_to_fix;  // true positions, start first
  std::vector<Eigen::Vector2d> correct_fixes;
  std::vector<Eigen::Vector2d> wrong_fixes;
};

/// PNG or SVG by extension, written atomically.
void DrawRelocalizationFigure(const std::string& path, const std::string& title,
                              const std::vector<Eigen::Vector2d>& map_positions,
                              const std::vector<StartDrawing>& starts);

}  // namespace keyplace::cli
