#pragma once
// The ground truth of a query log: the corrected pose of each of its scans, either the log's own
// (a corrected log) or, for a raw log, taken from a corrected log through a raw -> corrected index
// file (the `*-raw-to-corrected.tsv` files of the data sets).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

struct GroundTruth {
  std::string truth_log;  // path of the corrected log the poses come from
  // FileFingerprint ("crc32:<hex>:<bytes>") of that log: compared with GlobalMap::source_hash to
  // tell whether the queries meet the map's own log (TruthIsMapLog).
  std::string truth_log_hash;
  // The corrected poses of that log, in its scan order, from its scan truth_first_scan on (all of
  // them, unless the truth is a query log's own poses after a range cut).
  std::vector<Pose2> truth_poses;
  // Scan index in the truth log's file of truth_poses[0].
  std::size_t truth_first_scan = 0;
  // Per scan of the query log (its order, after any range cut): index into truth_poses, or -1.
  std::vector<int> truth_index_of_scan;
  // The index pairs that fall inside the query log's scans, with raw_index relative to them.
  std::vector<IndexPair> pairs;

  bool Has(std::size_t scan) const {
    return scan < truth_index_of_scan.size() && truth_index_of_scan[scan] >= 0;
  }
  const Pose2& Pose(std::size_t scan) const { return truth_poses[truth_index_of_scan[scan]]; }
  std::optional<Pose2> PoseIfAny(std::size_t scan) const {
    return Has(scan) ? std::optional<Pose2>(Pose(scan)) : std::nullopt;
  }
  // The index in the truth log's file of the truth pose of query scan `scan` (which must Has()):
  // what the self-match rule compares with a map's file-absolute scan indices.
  int TruthScan(std::size_t scan) const {
    return truth_index_of_scan[scan] + static_cast<int>(truth_first_scan);
  }
  std::size_t Count() const;  // scans with a truth pose
};

/// The log's own corrected poses; scans[0] of `log` is scan `first_scan` of its file (a range
/// cut). `log_hash`: the log's fingerprint when the caller has it (LogInputs::source_hash), else
/// empty and CarmenLog::fingerprint is taken, or for a log built in memory with a path that
/// file's FileFingerprint (left empty for a log without a path). Throws
/// std::invalid_argument naming the log when it has no corrected poses.
GroundTruth TruthFromOwnPoses(const CarmenLog& log, std::size_t first_scan = 0,
                              const std::string& log_hash = "");

/// The corrected poses of `truth_path` for the scans of `log`, whose scans[0] is scan
/// `first_scan` of its file, paired by the raw -> corrected index file `index_path`. Pairs outside
/// either log are an error naming the index file, the pair and both logs' sizes
/// (`file_scans`: scans in the query log's file).
GroundTruth TruthFromIndex(const CarmenLog& log, std::size_t first_scan, std::size_t file_scans,
                           const std::string& truth_path, const std::string& index_path);

/// TruthFromOwnPoses (with `log_hash`) when `truth_path` and `index_path` are both empty, else
/// TruthFromIndex; throws when only one of them is given.
GroundTruth LoadGroundTruth(const CarmenLog& log, std::size_t first_scan, std::size_t file_scans,
                            const std::string& truth_path, const std::string& index_path,
                            const std::string& log_hash = "");

/// Whether the truth comes from the log `map` was built from: then its scan indices and the
/// map's name the same scans and the self-match rule applies; otherwise the queries are another
/// recording (protocol (d)) and no map place can be a self-match. Compares the file fingerprints;
/// a map without one (older maps) is compared by file name.
bool TruthIsMapLog(const GlobalMap& map, const GroundTruth& truth);

}  // namespace keyplace
