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

namespace keyplace {

struct GroundTruth {
  std::string truth_log;  // path of the corrected log the poses come from
  // All corrected poses of that log, in its scan order.
  std::vector<Pose2> truth_poses;
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
  std::size_t Count() const;  // scans with a truth pose
};

/// The log's own corrected poses. Throws std::invalid_argument naming the log when it has none.
GroundTruth TruthFromOwnPoses(const CarmenLog& log);

/// The corrected poses of `truth_path` for the scans of `log`, whose scans[0] is scan
/// `first_scan` of its file, paired by the raw -> corrected index file `index_path`. Pairs outside
/// either log are an error naming the index file, the pair and both logs' sizes
/// (`file_scans`: scans in the query log's file).
GroundTruth TruthFromIndex(const CarmenLog& log, std::size_t first_scan, std::size_t file_scans,
                           const std::string& truth_path, const std::string& index_path);

/// TruthFromOwnPoses when `truth_path` and `index_path` are both empty, else TruthFromIndex;
/// throws when only one of them is given.
GroundTruth LoadGroundTruth(const CarmenLog& log, std::size_t first_scan, std::size_t file_scans,
                            const std::string& truth_path, const std::string& index_path);

}  // namespace keyplace
