#pragma once
// The report's figure sections (HTML), ours in place of the paper's.

#include <string>

#include "report_context.hpp"

namespace keyplace::cli {

/// Figures 3-5: the map of each corrected log (drawn by keyplace map --png).
std::string MapFigures(const ReportContext& context);

/// Figures 6-7: keypoint stability in one submap of the first corrected log, drawn into
/// context.figures_dir; a failure becomes a note and a warning.
std::string StabilityFigures(ReportContext& context);

/// Figure 8: mapping criteria over s_min and l_g, drawn from the sweep results.
std::string Figure8(ReportContext& context);

/// Figure 9: precision and recall over mu and gamma_min (FR079), drawn from the sweep results.
std::string Figure9(ReportContext& context);

/// The kidnapped robot's figures (drawn by keyplace relocalize --figure), corrected and raw log of
/// each data set.
std::string RelocalizationFigures(const ReportContext& context);

/// Figures 10-12: SLAM on the raw logs (drawn by keyplace slam --figures).
std::string SlamFigures(const ReportContext& context);

}  // namespace keyplace::cli
