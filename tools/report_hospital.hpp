#pragma once
// The report's section on the Freiburg hospital bag: SLAM in a building nobody tuned keyplace on
// (issue 17's check set), with its relation error beside the published ones.

#include <string>

#include "report_context.hpp"

namespace keyplace::cli {

/// Loops, relation errors (ours and published) and the trajectory of keyplace slam on the bag, or
/// a note saying how to make them.
std::string HospitalSection(const ReportContext& context);

}  // namespace keyplace::cli
