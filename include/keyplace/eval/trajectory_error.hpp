#pragma once
// Trajectory error curves of paper Section 6.2.2 (after Sturm et al. 2012): RPE RMSE as a
// function of the index interval Delta (Eq. 13-14) and the ATE of every pose after SE(2)
// alignment (Eq. 15), as a function of path length. Complements relation_error.hpp, whose
// EvaluateDrift gives the ATE summary and the alignment used here.

#include <cstddef>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/relations.hpp"

namespace keyplace {

/// Estimated and true poses of the same scans, in trajectory order (index i of both vectors is
/// the same scan).
struct PairedTrajectory {
  std::vector<Pose2> estimated;  // P_i
  std::vector<Pose2> truth;      // Q_i
  std::vector<std::size_t> raw_index;
};

/// Pairs through raw -> corrected index pairs, sorted by corrected index. Throws
/// std::invalid_argument naming the index when a pair is out of range.
PairedTrajectory PairTrajectory(const std::vector<Pose2>& estimate_by_raw_index,
                                const std::vector<Pose2>& corrected_by_corrected_index,
                                const std::vector<IndexPair>& pairs);

struct RpePoint {
  std::size_t delta = 0;  // index interval
  std::size_t count = 0;  // m = n - delta
  double translation_rmse_m = 0.0;
  double rotation_rmse_deg = 0.0;
};

/// E_i = (Q_i^-1 Q_{i+Delta})^-1 (P_i^-1 P_{i+Delta}); RMSE of |Trans(E_i)| and of |rot(E_i)|
/// for each Delta (Deltas >= n give count 0). Throws std::invalid_argument when the two
/// trajectories differ in length or a Delta is 0.
std::vector<RpePoint> RelativePoseErrorCurve(const PairedTrajectory& trajectory,
                                             const std::vector<std::size_t>& deltas);

struct AtePoint {
  double path_length_m = 0.0;  // along the true trajectory up to this pose
  double translation_m = 0.0;  // |Trans(F_i)|, F_i = Q_i^-1 A P_i
  double rotation_deg = 0.0;
};

struct AteSeries {
  Pose2 alignment;  // A: least-squares SE(2) map of estimated positions onto the true ones
  double translation_rmse_m = 0.0;
  double rotation_rmse_deg = 0.0;
  std::vector<AtePoint> points;
};

/// Eq. (15) for every pose, with A from the closed-form alignment of EvaluateDrift.
AteSeries AbsoluteTrajectoryErrors(const PairedTrajectory& trajectory);

}  // namespace keyplace
