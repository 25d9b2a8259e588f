#pragma once
// The paper's Figures 8 and 9 from the results of `keyplace sweep mapping|place`
// (DIR/results.json), drawn as PNG line charts.

#include <string>

namespace keyplace::cli {

/// Figure 8: the mapping criteria (compression, scans and keypoints per submap, distribution,
/// submaps, time per submap) against s_min, one line per l_g. Throws std::invalid_argument naming
/// the file and field when `results_json` is not a `sweep mapping` result.
void DrawFigure8(const std::string& results_json, const std::string& png_path,
                 const std::string& title);

/// Figure 9: precision and recall against gamma_min, one line per mu (the rows of the first
/// lambda and mapping setting in the file, which are named in the chart titles). Throws as above
/// for anything but a `sweep place` result.
void DrawFigure9(const std::string& results_json, const std::string& png_path,
                 const std::string& title);

}  // namespace keyplace::cli
