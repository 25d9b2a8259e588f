#pragma once
// The report's section on map size (issue 35): FR079's queries among distractor submaps copied
// from the other buildings' maps, with the exact path and with retrieval, from 10³ submaps up.

#include <string>
#include <vector>

#include "report_context.hpp"
#include "report_plan.hpp"

namespace keyplace::cli {

/// The localize JSON of FR079 among distractors: `submaps` in all, `retrieval` exact or words.
std::string MapSizeJson(const ReportSettings& settings, const std::string& retrieval, int submaps);

/// The map sizes of the section: 10³ (quick), 10³ to 10⁵ (full).
std::vector<int> MapSizes(const ReportSettings& settings);

/// One keyplace localize step per size and retrieval, when FR079 and at least one other data set
/// are in the report (the others' maps are the distractors); none otherwise.
std::vector<ReportStep> PlanMapSizeSteps(const ReportSettings& settings);

/// The table (query time, recall, precision, preparation per size and retrieval) and the
/// log-log figure, drawn into context.figures_dir.
std::string MapSizeSection(ReportContext& context);

}  // namespace keyplace::cli
