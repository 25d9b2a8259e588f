#include "keyplace/eval/ground_truth.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "io/file_fingerprint.hpp"

namespace keyplace {

std::size_t GroundTruth::Count() const {
  return static_cast<std::size_t>(std::count_if(truth_index_of_scan.begin(),
                                                truth_index_of_scan.end(),
                                                [](int index) { return index >= 0; }));
}

GroundTruth TruthFromOwnPoses(const CarmenLog& log, std::size_t first_scan,
                              const std::string& log_hash) {
  if (!log.corrected) {
    throw std::invalid_argument(log.path +
                                " has no corrected poses: give --truth CORRECTED_LOG and --index "
                                "RAW_TO_CORRECTED.tsv");
  }
  GroundTruth truth;
  truth.truth_log = log.path;
  // The reader's fingerprint first: a log read from a pipe cannot be read again. A log built in
  // memory (no path) has no file to fingerprint.
  if (!log_hash.empty()) {
    truth.truth_log_hash = log_hash;
  } else if (!log.fingerprint.empty()) {
    truth.truth_log_hash = log.fingerprint;
  } else if (!log.path.empty()) {
    truth.truth_log_hash = FileFingerprint(log.path);
  }
  truth.truth_first_scan = first_scan;
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    const LogScan& scan = log.scans[k];
    if (!scan.corrected_pose) {
      throw std::invalid_argument(log.path + ":" + std::to_string(scan.line) +
                                  ": scan has no corrected pose");
    }
    truth.truth_poses.push_back(*scan.corrected_pose);
    truth.truth_index_of_scan.push_back(static_cast<int>(k));
    truth.pairs.push_back({k, k});
  }
  return truth;
}

GroundTruth TruthFromIndex(const CarmenLog& log, std::size_t first_scan, std::size_t file_scans,
                           const std::string& truth_path, const std::string& index_path) {
  const CarmenLog truth_log = ReadCarmenLogWithScans(truth_path);
  if (!truth_log.corrected) {
    throw std::invalid_argument(truth_path + ": --truth must be a corrected log (VERTEX2 lines)");
  }
  GroundTruth truth = TruthFromOwnPoses(truth_log);
  truth.pairs.clear();
  truth.truth_index_of_scan.assign(log.scans.size(), -1);
  for (const IndexPair& pair : ReadIndexPairs(index_path)) {
    if (pair.raw_index >= file_scans || pair.corrected_index >= truth.truth_poses.size()) {
      std::string message = index_path;
      message += ": pair " + std::to_string(pair.raw_index);
      message += " -> " + std::to_string(pair.corrected_index);
      message += " lies outside " + log.path + " (" + std::to_string(file_scans) + " scans)";
      message += " or " + truth_path + " (" + std::to_string(truth.truth_poses.size()) + " scans)";
      throw std::invalid_argument(message);
    }
    if (pair.raw_index < first_scan || pair.raw_index - first_scan >= log.scans.size()) continue;
    const std::size_t scan = pair.raw_index - first_scan;
    truth.truth_index_of_scan[scan] = static_cast<int>(pair.corrected_index);
    truth.pairs.push_back({scan, pair.corrected_index});
  }
  return truth;
}

GroundTruth LoadGroundTruth(const CarmenLog& log, std::size_t first_scan, std::size_t file_scans,
                            const std::string& truth_path, const std::string& index_path,
                            const std::string& log_hash) {
  if (truth_path.empty() != index_path.empty()) {
    throw std::invalid_argument("--truth and --index must be given together");
  }
  if (truth_path.empty()) return TruthFromOwnPoses(log, first_scan, log_hash);
  return TruthFromIndex(log, first_scan, file_scans, truth_path, index_path);
}

bool TruthIsMapLog(const GlobalMap& map, const GroundTruth& truth) {
  if (!map.source_hash.empty()) return map.source_hash == truth.truth_log_hash;
  return map.source_log == std::filesystem::path(truth.truth_log).filename().string();
}

}  // namespace keyplace
