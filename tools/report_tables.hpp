#pragma once
// The report's tables, each ours beside the paper's (HTML sections of the page). Mapping tables
// in report_mapping_tables.cpp, place recognition tables in report_place_tables.cpp.

#include <string>

#include "report_context.hpp"

namespace keyplace::cli {

/// Table II: mapping criteria of the corrected logs (overlap criterion only, and all criteria).
std::string TableII(const ReportContext& context);

/// Table VI: mapping criteria of the raw logs (ICP poses).
std::string TableVI(const ReportContext& context);

/// Table IX (mapping criteria of the SLAM maps) and the loops of Section 6.2.2.
std::string TableIX(const ReportContext& context);

/// Table V: the paper's parameters beside our defaults.
std::string TableV();

/// Tables III, IV (corrected queries) and VII, VIII (`raw` queries) at `lambda_m`.
std::string LocalizationTable(const ReportContext& context, bool raw, double lambda_m,
                              const std::string& anchor, const std::string& title);

/// Table X: P_GL and P_CL of ours and of TIP-FLIRT.
std::string TableX(const ReportContext& context);

/// The kidnapped robot (keyplace relocalize, not in the paper): one row per data set and log kind
/// (corrected, raw), a "not computed" row when its JSON is missing.
std::string RelocalizationTable(const ReportContext& context);

}  // namespace keyplace::cli
