#pragma once
// The kidnapped-robot benchmark: from each of N starts spread over a query log, a Relocalizer
// that knows nothing is fed scans and odometry until it declares a fix or gives up (a cap on the
// distance travelled, or the end of the log); after its first fix it keeps running for a further
// stretch and every fix it reports is checked against the ground truth. This is how a robot
// lives with a localizer: a stream of scans, not isolated queries.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/common/result_fields.hpp"
#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/localization/initial_pose.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace {

struct RelocalizationOptions {
  int starts = 50;
  double give_up_m = 50.0;  // odometry distance without a fix after which a start is given up
  double follow_m = 20.0;   // odometry distance after the first fix during which fixes are checked
  // Protocol (a): the localizer never matches a map submap that shares a scan with its current
  // query. Only meaningful when the query log is the map's own log (TruthIsMapLog).
  bool exclude_shared_scans = true;
  double correct_m = 0.5;  // a fix is correct within these of the truth
  double correct_deg = 10.0;
  double revisit_m = 1.5;  // a start has a revisit when its path comes this close to a map scan
  double revisit_deg = 45.0;
  // A start with a revisit has room when it has at least this much path left after the revisit
  // (evaluation.revisit_room_m).
  double revisit_room_m = 10.0;
  double confident = 0.9;  // a fix at least this confident is "confident"
  // A fix is checked at the nearest scan with a truth pose at most this many scans away
  // (evaluation.truth_max_gap_scans); fixes with none are not counted.
  int truth_max_gap_scans = 50;
};

/// The benchmark's options for `starts` starts from the evaluation settings (give_up_m, follow_m,
/// the revisit radius, angle and room, truth_max_gap_scans), as `keyplace relocalize` runs it: map
/// submaps sharing a scan with the query are skipped when `shared_scan_rule` is asked for and
/// the query log is the map's own (a scan index of another recording says nothing about this
/// one). Throws std::invalid_argument when starts < 1.
RelocalizationOptions RelocalizationOptionsFor(const EvaluationConfig& evaluation, int starts,
                                               bool shared_scan_rule, bool query_log_is_map_log);

/// One fix the relocalizer reported (at an update where a query was answered).
struct FixEvent {
  int scan = 0;          // query-log scan the fix was reported at (index into the log's scans)
  int checked_scan = 0;  // the scan it was checked at (the nearest with a truth pose)
  Pose2 T_world_robot;
  Pose2 truth;
  double confidence = 0.0;
  // As reported at `scan`: InitialPoseOf(the update), what a robot would publish on
  // /initialpose (frame "map"; pose T_world_robot at `scan`, covariance from the matches).
  InitialPose initial_pose;
  bool correct = false;
  bool first = false;  // the start's first fix
};

/// One start.
struct StartRecord {
  int start_scan = 0;
  int end_scan = 0;      // one past the last scan fed
  bool revisit = false;  // the path before the cap passes a map scan the localizer may match
  double distance_to_revisit_m = 0.0;  // odometry distance to the first such scan
  // Odometry distance from that scan to where the start stops without a fix (give_up_m or the
  // log's end): the path the localizer has on ground the map has seen, at most.
  double room_after_revisit_m = 0.0;
  bool fixed = false;
  int scans_to_fix = 0;  // scans fed up to and including the first fix
  double distance_to_fix_m = 0.0;
  bool first_fix_checked = false;  // a truth pose was near enough to check it
  bool first_fix_correct = false;
  int answers = 0;           // answers: queries answered and searches of the whole map found
  int answers_accepted = 0;  // of them accepted by the place recognizer
  int answers_weak = 0;      // of them not accepted but naming a weak answer
  std::vector<FixEvent> fixes;
  int wrong_fixes = 0;
  int lost = 0;                   // "lost" signals
  int lost_on_correct_track = 0;  // of them while the fix was right
  int lost_on_wrong_track = 0;    // "lost" while the fix was wrong (the signal did its job)
  double update_seconds_mean = 0.0;
  double update_seconds_max = 0.0;
  // Searches of the whole map run within the updates (LocalizerConfig::map_search_window_m) and
  // the time they took, part of the updates' time.
  int map_searches = 0;
  double map_search_seconds = 0.0;
};

struct RelocalizationSummary {
  std::size_t starts = 0;
  std::size_t starts_with_revisit = 0;
  std::size_t fixed = 0;               // starts with a first fix
  std::size_t fixed_with_revisit = 0;  // of the starts with a revisit
  double fixed_fraction = 0.0;         // fixed_with_revisit / starts_with_revisit
  // The same over the starts with room after their revisit (RelocalizationOptions::revisit_room_m).
  std::size_t starts_with_room = 0;
  std::size_t fixed_with_room = 0;
  double fixed_fraction_with_room = 0.0;
  std::size_t fixes = 0;
  std::size_t wrong_fixes = 0;
  double wrong_fix_rate = 0.0;            // wrong_fixes / fixes
  std::size_t wrong_first_fixes = 0;      // starts whose first fix was wrong
  bool wrong_fix_confident = false;       // a wrong fix had confidence >= options.confident
  double wrong_fix_confidence_max = 0.0;  // 0 without wrong fixes
  double distance_to_fix_median_m = 0.0;  // over fixed starts
  double distance_to_fix_p90_m = 0.0;
  double scans_to_fix_median = 0.0;
  // From the first scan the map has seen to the first fix (starts with a revisit that were fixed):
  // what the localizer adds to the wait for a known place.
  double distance_after_revisit_median_m = 0.0;
  double distance_after_revisit_p90_m = 0.0;
  double update_seconds_mean = 0.0;  // per AddScan with keypoints given, over all updates
  double update_seconds_max = 0.0;
  // Searches of the whole map, their mean time, and the updates' mean time without them (what
  // a robot's node spends per scan: RelocalizationNode runs the searches on a thread of their
  // own).
  std::size_t map_searches = 0;
  double map_search_seconds_mean = 0.0;
  double update_seconds_mean_without_search = 0.0;
  std::size_t lost_signals = 0;  // the two below, and those with no truth to tell
  std::size_t lost_on_correct_track = 0;
  std::size_t lost_on_wrong_track = 0;
};

/// The summary's figures, named as the keys of `keyplace relocalize --json` and the attributes
/// of Python's RelocalizationEvaluation.
const ResultFields<RelocalizationSummary>& RelocalizationSummaryFields();

/// The figures of one start and of one fix (the poses and covariance aside): the columns of
/// `keyplace relocalize --tsv` / `--fixes` and the properties of Python's StartRecord / FixEvent.
const ResultFields<StartRecord>& StartRecordFields();
const ResultFields<FixEvent>& FixEventFields();

/// Progress: (starts done, starts in all), called from one thread at a time, counting up.
using StartProgress = std::function<void(std::size_t, std::size_t)>;

/// Runs the benchmark on `inputs` (poses = the odometry fed to the localizer, keypoints
/// extracted) against `map`. With exclude_shared_scans, the localizer's scan ids are the truth
/// file indices of the scans (GroundTruth::TruthScan) and map submaps sharing one with the
/// current query are skipped. The starts run in parallel (TBB; tbb::global_control bounds the
/// threads), each on its own copy of one Relocalizer (the recognizer is shared); the records, in
/// start order, do not depend on the thread count except update_seconds_mean / _max, which time
/// each AddScan call while other starts run beside it.
std::vector<StartRecord> RunRelocalization(const GlobalMap& map, const LogInputs& inputs,
                                           const GroundTruth& truth, const LocalizerConfig& config,
                                           const RelocalizationOptions& options,
                                           const StartProgress& progress = {});

RelocalizationSummary SummarizeRelocalization(const std::vector<StartRecord>& records,
                                              const RelocalizationOptions& options);

/// The first fix of the first start that got one: what a robot would publish on /initialpose.
struct FirstFix {
  int start_scan = 0;  // the start (StartRecord::start_scan)
  FixEvent fix;
};
/// Nothing when no start got a fix.
std::optional<FirstFix> FirstFixOf(const std::vector<StartRecord>& records);

}  // namespace keyplace
