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

/// "ICP vs odometry median ... m, ... deg per step; 99 % ..." (or why there is no figure).
void PrintStepDisagreement(const OdometryStepDisagreement& summary);
/// steps, median_m, p99_m, median_deg, p99_deg (null figures without steps).
nlohmann::json StepDisagreementJson(const OdometryStepDisagreement& summary);

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
/// One row per step (the first scan: a zero step): the later scan's file index, stamp, ICP status,
/// inlier ratio, residual, iterations, degeneracy, the ICP step and the odometry step (dx_m, dy_m,
/// dtheta_rad in the earlier robot frame; nan without odometry) and their disagreement (m, deg).
void WriteStepsTsv(const std::string& path, const std::vector<OdometryStep>& steps);
/// timestamp_s, x_m, y_m, theta_rad per pose.
void WriteTrajectoryTsv(const std::string& path, const std::vector<TimedPose>& trajectory);

}  // namespace keyplace::cli
