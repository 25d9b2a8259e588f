#pragma once
// What `keyplace odometry` prints and writes: the run statistics, the relation errors and the
// drift of the ICP and raw-odometry trajectories, their JSON forms, and the TSV files.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "keyplace/eval/odometry_evaluation.hpp"
#include "keyplace/io/relations.hpp"

namespace keyplace::cli {

/// "scans ... of ... (... order)", registered, recovered, fallbacks, degenerate, key scans, time
/// per scan.
void PrintOdometryRun(const OdometryRun& run);
/// The run statistics as flat keys (scans, scans_in_log, registered, ..., iterations_mean).
nlohmann::json OdometryRunJson(const OdometryRun& run);

/// "ICP relation error (...)" and "odometry relation error (...)", all / local / loop.
void PrintOdometryRelations(const OdometryRelationErrors& errors);
/// "drift against corrected poses (...)", one line per trajectory.
void PrintOdometryDrift(const OdometryDrift& drift);
/// pairs, consecutive statistics and ATE figures of one trajectory.
nlohmann::json DriftJson(const DriftReport& drift);

/// Per matched ICP relation: the file line, stamps, dt, local flag and both trajectories' errors
/// side by side (nan where the odometry trajectory did not match the relation).
void WriteRelationErrorsTsv(const std::string& path, const std::vector<Relation>& relations,
                            const OdometryRelationErrors& errors);
/// timestamp_s, x_m, y_m, theta_rad per pose.
void WriteTrajectoryTsv(const std::string& path, const std::vector<TimedPose>& trajectory);

}  // namespace keyplace::cli
