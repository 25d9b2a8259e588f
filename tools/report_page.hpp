#pragma once
// The report's page: one self-contained HTML document with every figure and table of the paper,
// ours beside the paper's, and the commands that made each artefact.

#include <string>

#include "report_context.hpp"

namespace keyplace::cli {

/// The whole page from the work directory's artefacts after the steps ran. Draws the figures
/// the report makes itself into context.figures_dir and adds what went wrong to
/// context.warnings (listed on the page). `run_seconds` is the duration shown in its header.
std::string BuildPage(ReportContext& context, double run_seconds);

}  // namespace keyplace::cli
