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

namespace keyplace::cli {

/// A row of Tables III/IV (corrected) or VII/VIII (raw queries, ICP): global localization with
/// mu = 10, gamma_min = 0.4.
struct PaperLocalizationRow {
  const char* table;
  double precision;
  double recall;
  double scans;    // scans per correct localization
  double seconds;  // time per localization
};
/// The row for `dataset` ("FR079", "FR101_r", ...) and lambda (0.05 or 0.1 m); nullptr when the
/// paper has none.
const PaperLocalizationRow* PaperLocalization(const std::string& dataset, double lambda_m);

/// Table X: P_GL and P_CL for FR079 and Intel (raw queries against the corrected map).
struct PaperPglPcl {
  double p_gl;
  double p_cl;
};
/// `method` "ours" with mu in {5, 10} and lambda in {0.05, 0.1}, or "tip-flirt" (mu, lambda
/// ignored). `dataset` may carry the "_r" suffix. nullptr when the paper has none.
const PaperPglPcl* PaperTableX(const std::string& dataset, const std::string& method, int mu,
                               double lambda_m);

}  // namespace keyplace::cli

namespace keyplace::cli {

/// Section 6.2.2: Table IX (mapping criteria of the SLAM-corrected raw maps) and the loop counts
/// and precisions of the loop-closure experiment, for FR079_r, FR101_r and Intel_r.
struct PaperSlamRow {
  double compression;
  double scans_per_submap;
  double keypoints_per_submap;
  double distribution;
  int submaps;
  double seconds_per_submap;
  int loops_detected;
  int loops_used;
  double precision_overlap_30;  // 73/82, 169/184, 503/572
  double precision_overlap_10;  // 82/82, 184/184, 569/572
};
/// nullptr for a data set the paper did not run SLAM on.
const PaperSlamRow* PaperSlam(const std::string& dataset);

}  // namespace keyplace::cli
