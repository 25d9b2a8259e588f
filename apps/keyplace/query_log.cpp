#include "query_log.hpp"

#include "cli_support.hpp"
#include "config_options.hpp"
#include "keyplace/config/log_inputs.hpp"

namespace keyplace::cli {

void AddQueryLogOptions(CLI::App* command, QueryLogOptions& options,
                        const std::string& poses_help) {
  command
      ->add_option("--log", options.log_path,
                   "Query log (corrected or raw CARMEN log, or ROS 1 or ROS 2 bag)")
      ->required()
      ->check(CLI::ExistingPath);
  command->add_option("--poses", options.poses, poses_help)
      ->check(CLI::IsMember({"corrected", "icp", "odometry"}))
      ->capture_default_str();
  command
      ->add_option("--truth", options.truth_path,
                   "Corrected log giving the ground truth of a raw query log")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--index", options.index_path,
                   "raw_index<TAB>corrected_index file relating --log to --truth")
      ->check(CLI::ExistingFile);
  command->add_option("--scans", options.scans,
                      "Query scans A:B of the log (a time split: the map of --scans 0:A, the "
                      "queries from A:)");
  command->add_flag("--skip-bad-lines", options.skip_bad_lines, kSkipBadLinesHelp);
  command->add_option("--cache", options.cache_dir, kCacheHelp);
  command
      ->add_option("--threads", options.threads,
                   "Worker threads (0 = all cores); the figures do not depend on it")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

QueryLog ReadQueryLog(const QueryLogOptions& options, const Config& config, bool truth_optional) {
  QueryLog query;
  query.input_options = LogInputOptionsFor(config);
  query.input_options.reading.skip_bad_lines = options.skip_bad_lines;
  if (!options.poses.empty()) query.input_options.poses = ParsePoseSource(options.poses);
  query.input_options.cache_dir = options.cache_dir;
  ApplyScanRange(options.scans, query.input_options);
  query.inputs = PrepareLogInputs(options.log_path, query.input_options, StageProgressBar());
  PrintInputsWarnings(query.inputs);
  const bool truth_available = !options.truth_path.empty() || query.inputs.log.corrected;
  if (!truth_available && truth_optional) return query;  // has_truth stays false
  // Without truth this throws, asking for --truth and --index.
  query.truth = LoadGroundTruth(query.inputs.log, query.inputs.first_scan, query.inputs.file_scans,
                                options.truth_path, options.index_path, query.inputs.source_hash);
  query.has_truth = true;
  return query;
}

}  // namespace keyplace::cli
