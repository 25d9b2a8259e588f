#pragma once
// The paper's published figures, to print beside ours.

#include <optional>
#include <string>

namespace keyplace::cli {

/// "FR079", "FR101", "Intel" for corrected logs and "FR079_r", ... for raw ones, recognised from
/// the log's file name (fr079-corrected.log.gz, intel-raw.log, ...); nullopt otherwise.
std::optional<std::string> DatasetName(const std::string& log_path);

/// A row of Table II (corrected) or Table VI (raw, ICP): mapping criteria.
struct PaperMappingRow {
  const char* table;
  double compression;
  double scans_per_submap;
  double keypoints_per_submap;
  double distribution;
  int submaps;
  double seconds_per_submap;
};
/// nullptr for an unknown data set name.
const PaperMappingRow* PaperMapping(const std::string& dataset);

}  // namespace keyplace::cli
