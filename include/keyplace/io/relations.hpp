#pragma once
// Ground-truth relations of Kümmerle et al. (2009), "On measuring the accuracy of SLAM
// algorithms", and the raw -> corrected scan index maps of ../shared/data.

#include <cstddef>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// One line `t_a t_b dx dy dz droll dpitch dyaw`: the true pose of the robot at time t_b in the
/// frame of the robot at time t_a (z, roll, pitch are ignored; the files hold 0 there).
struct Relation {
  double timestamp_a_s = 0.0;  // ipc_timestamp of a raw-log scan, as written
  double timestamp_b_s = 0.0;
  Pose2 T_a_b;
  std::size_t line = 0;  // 1-based line number in the file
};

/// Reads a relation file. Blank lines and lines starting with '#' are skipped. Throws
/// std::invalid_argument naming file, line and field on malformed lines, std::runtime_error when
/// the file cannot be opened.
std::vector<Relation> ReadRelations(const std::string& path);

/// One row of a `*-raw-to-corrected.tsv` file (0-based laser-line indices).
struct IndexPair {
  std::size_t raw_index = 0;
  std::size_t corrected_index = 0;
};

/// Reads `raw_index<TAB>corrected_index` rows (a header line starting with a letter is skipped).
/// Throws std::invalid_argument naming file, line and field on malformed lines.
std::vector<IndexPair> ReadIndexPairs(const std::string& path);

}  // namespace keyplace
