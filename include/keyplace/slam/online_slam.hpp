#pragma once
// Online SLAM with loop closure by place recognition (paper Section 6.2.2). Scans are eaten one
// at a time: ICP scan odometry -> local mapping (Algorithm 1) -> each completed submap becomes a
// node of an SE(2) pose graph (odometry edge to the previous submap) and is queried against the
// submaps mapped so far, its recent neighbours excluded -> a verified match is refined by ICP
// between the submaps' point clouds and given the best-overlapping partner among the matched
// submap and its neighbours (loop_refinement.hpp) -> a gated loop becomes a loop edge -> the
// graph is optimised (Ceres, robust loop loss, outlier loops switched off) -> the
// map's submap poses, and with them every scan's pose, follow the optimised submap origins.

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/local_mapper.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "keyplace/registration/scan_odometry.hpp"
#include "keyplace/slam/loop_refinement.hpp"
#include "keyplace/slam/pose_graph.hpp"

namespace keyplace {

struct SlamConfig {
  ScanOdometryConfig odometry;   // ICP scan odometry (docs/REGISTRATION.md)
  MappingConfig mapping;         // submaps (paper Table V)
  PlaceRecognitionConfig place;  // loop detection (paper Table V; our default preset)
  PoseGraphConfig graph;         // back end
  // Dense ICP refinement of each detected loop and choice of its partner submap among the matched
  // one and its temporal neighbours (docs/SLAM.md, "Loop refinement"). Runs before the gate.
  LoopRefinementConfig loop_refinement;

  // --- which submaps a completed submap is matched with
  // Not with the last `exclude_recent_submaps` submaps before it, nor with submaps whose origin
  // lies less than `exclude_recent_path_m` of travelled path (ICP) behind its own origin: those
  // are neighbours that overlap by construction, not loops.
  int exclude_recent_submaps = 10;
  double exclude_recent_path_m = 10.0;
  // With retrieval `words` (place.retrieval auto), a loop query also pairs the eligible submaps
  // whose estimated origin lies within this of its own (at most place.retrieval_places, nearest
  // first), whatever their words rank: a loop the estimate already expects is not left to the
  // words (docs/SLAM.md, "Retrieval in loop queries"). 0: the words alone.
  double loop_search_near_m = 3.0;
  // Query each completed submap with the keypoints of all its scans, as `keyplace localize`
  // does, instead of its ~18 stable keypoints (issue 17: a building whose stable keypoints do not
  // recur got no loop). Applies when place.query_keypoints = all_scans (the default presets; the
  // paper preset queries with stable keypoints, and so does the loop detector then). Such a loop
  // passes the localize thresholds (place.min_gamma_all_scans) and then the dense point overlap
  // check loop_refinement.min_point_overlap, chosen for it on FR079_r and Intel_r (docs/SLAM.md,
  // "All-scan loop queries").
  bool all_scan_loop_queries = true;

  // --- loop acceptance: a loop is a PlaceMatch with `found` (verified, not ambiguous); it becomes
  // a graph edge when it also passes the gate: the measured T_ref_cur agrees with the current
  // graph estimate within gate_base_m + gate_per_path * path (m) and gate_base_rad +
  // gate_per_path_rad * path (rad), `path` being the travelled path between the two submaps. The
  // allowance grows with the path because drift does. 0 for gate_base_m disables the gate.
  double gate_base_m = 2.0;
  double gate_per_path = 0.1;       // m of allowed disagreement per m of path
  double gate_base_rad = 0.35;      // 20 deg
  double gate_per_path_rad = 0.01;  // rad per m of path

  // --- information of the edges (standard deviations; diag information 1 / sigma^2)
  // Odometry edge between consecutive submap origins with translation d (m) and rotation a (rad):
  // sigma_xy = odometry_sigma_base_m + odometry_sigma_per_m * d,
  // sigma_theta = odometry_sigma_base_rad + odometry_sigma_per_rad * a + odometry_sigma_rad_per_m
  // * d.
  double odometry_sigma_base_m = 0.02;
  double odometry_sigma_per_m = 0.05;
  double odometry_sigma_base_rad = 0.005;
  double odometry_sigma_per_rad = 0.05;
  double odometry_sigma_rad_per_m = 0.01;
  // Loop edge: sigma = loop_sigma_* * sqrt(loop_reference_consensus / consensus), so that a loop
  // backed by more RANSAC inliers weighs more.
  double loop_sigma_m = 0.05;
  double loop_sigma_rad = 0.02;
  int loop_reference_consensus = 20;

  // --- when to optimise: after every `optimize_every_loops` accepted loops (1 = after each, as
  // the paper updates its graph each time a loop is detected), and once more in Finish(). A loop
  // the estimate already meets, its whitened residual at most `defer_loop_residual_sigmas`, is not
  // counted: it would move the estimate by less than its noise, and waits for the next loop that
  // is counted or Finish() (Intel_r: 51 optimisations instead of 499, 1.0 s instead of 9.0 s, the
  // same relation error; docs/SLAM.md). 0 counts every loop.
  int optimize_every_loops = 1;
  double defer_loop_residual_sigmas = 1.0;
};

/// Throws std::invalid_argument naming the first invalid field (nested configs included).
void Validate(const SlamConfig& config);

/// One detected loop (a `found` place match of a completed submap).
struct LoopClosure {
  int query_submap = 0;        // the completed submap (current)
  int reference_submap = 0;    // the loop partner: the matched submap or one of its neighbours
  Pose2 T_ref_cur;             // the query's origin in the frame of the partner's origin (final)
  int matched_submap = 0;      // the submap place recognition matched
  Pose2 T_matched_cur_ransac;  // place recognition's (RANSAC) estimate against it
  bool refined = false;        // T_ref_cur is the ICP refinement (else composed from RANSAC)
  IcpStatus refine_status = IcpStatus::kTooFewPoints;  // of the ICP against the partner
  double refine_inlier_ratio_initial = 0.0;  // current-cloud inliers at the initial estimate
  double refine_inlier_ratio = 0.0;          // ... at T_ref_cur
  double refine_correction_m = 0.0;          // ICP correction of the initial estimate
  double refine_correction_rad = 0.0;
  double point_overlap = 0.0;  // PointOverlap of the partner and current clouds at T_ref_cur
  int pairs = 0;
  int consensus = 0;
  double gamma = 0.0;
  double confidence = 0.0;
  bool accepted = false;            // passed the gate and became a graph edge
  int edge = -1;                    // pose-graph edge index when accepted
  double gate_translation_m = 0.0;  // disagreement with the graph estimate at detection
  double gate_rotation_rad = 0.0;
  double path_between_m = 0.0;  // travelled path between the two submap origins
};

/// What happened with one scan.
struct SlamStep {
  ScanOdometryResult odometry;
  bool submap_completed = false;
  int submap_id = -1;      // the completed submap
  int loop = -1;           // index into loops() when the completed submap closed a loop
  bool optimized = false;  // the graph was optimised after this scan
  PlaceMatch match;        // the recognizer's answer (when a submap was completed and queried)
};

struct SlamStats {
  std::size_t scans = 0;
  std::size_t submaps = 0;
  std::size_t queries = 0;  // completed submaps matched against the map (eligible places > 0)
  std::size_t loops_detected = 0;
  std::size_t loops_accepted = 0;  // passed the gate
  // Of those, loops the estimate already met within their sigmas when accepted: optimised with
  // the next loop that does not, or in Finish(), not at once.
  std::size_t loops_deferred = 0;
  std::size_t loops_refined = 0;          // loop transform refined by ICP
  std::size_t loops_partner_changed = 0;  // partner is a neighbour of the matched submap
  // Found matches not taken as loops by the point-overlap verification
  // (loop_refinement.min_point_overlap; always 0 when it is 0).
  std::size_t loops_rejected_by_point_overlap = 0;
  std::size_t optimizations = 0;
  std::size_t solves = 0;
  std::size_t loops_rejected_by_graph = 0;  // switched off at the moment
  double seconds_odometry = 0.0;
  double seconds_mapping = 0.0;
  double seconds_recognition = 0.0;      // place recognition and loop refinement
  double seconds_loop_refinement = 0.0;  // of which: ICP refinement and partner choice
  double seconds_optimization = 0.0;
};

class OnlineSlam {
 public:
  /// Throws std::invalid_argument (Validate) for an invalid config. `features` configures the
  /// FLIRT extraction of the AddScan that takes no keypoints.
  explicit OnlineSlam(const SlamConfig& config = {}, const FlirtConfig& features = {});
  ~OnlineSlam();
  OnlineSlam(const OnlineSlam&) = delete;
  OnlineSlam& operator=(const OnlineSlam&) = delete;

  /// Adds the next scan (processing order) with the robot's odometry pose when there is one and
  /// its FLIRT keypoints (laser frame). `scan_index` is the caller's index of the scan (e.g. its
  /// file index), kept in the submaps and poses. A scan the local mapper refuses (a non-finite
  /// pose, a beam that would grow its grid beyond mapping.max_grid_cells) throws
  /// std::invalid_argument and leaves the map and the submap in progress as they were (the ICP
  /// odometry keeps the scan).
  SlamStep AddScan(int scan_index, const LaserScan& scan, const std::optional<Pose2>& T_odom_robot,
                   const std::vector<Keypoint>& keypoints);

  /// The same with the keypoints extracted here (FLIRT with the constructor's `features`, their
  /// duplicate box along the axes of the odometry frame, as keyplace prepares a log's keypoints),
  /// as GlobalLocalizer::AddScan takes a scan: scan and odometry in, the step's poses out.
  SlamStep AddScan(int scan_index, const LaserScan& scan, const std::optional<Pose2>& T_odom_robot);

  /// Optimises the graph once more (if it has loops) and updates the map's poses.
  void Finish();

  /// The map so far: completed submaps, their poses P following the optimised origins.
  const GlobalMap& map() const { return map_; }
  /// Optimised T_world_robot of every scan added so far, in processing order, with its
  /// scan_index and timestamp. Scans after the last completed submap follow that submap.
  struct ScanPose {
    int scan_index = 0;
    double timestamp_s = 0.0;
    Pose2 T_world_robot;
    Pose2 T_world_robot_icp;  // the ICP odometry pose (before any correction)
    int submap = -1;          // the submap the scan belongs to (-1: not completed yet)
  };
  std::vector<ScanPose> Trajectory() const;
  /// The same for the last scan added (as Trajectory().back(), in constant time); the first
  /// scan's pose before any.
  ScanPose LatestPose() const;

  const std::vector<LoopClosure>& loops() const { return loops_; }
  /// The observed area of a completed submap: the cells of its stability grid G that some beam
  /// ended in or crossed, in the submap frame (the binary grids of the paper's Eq. 7).
  const OccupancySummary& ObservedArea(int submap) const {
    return observed_areas_[static_cast<std::size_t>(submap)];
  }
  /// True when an accepted loop's edge is enabled in the graph now (not switched off).
  bool LoopUsed(const LoopClosure& loop) const;
  const PoseGraph& graph() const { return graph_; }
  const SlamStats& stats() const { return stats_; }
  // The config given, with place.retrieval auto resolved (words).
  const SlamConfig& config() const { return config_; }

 private:
  // Loop queries carry all-scan keypoints (all_scan_loop_queries with all-scan place queries).
  bool QueriesWithAllScans() const;
  void CompleteSubmap(SlamStep& step);
  // Refines a found match and chooses its partner; fills the loop's transform and partner.
  void RefineAndChoosePartner(int id, std::size_t eligible, LoopClosure& loop);
  // Gates the loop, adds its edge when accepted and records it.
  void AddLoop(int id, double origin_path, LoopClosure loop);
  void Optimize();
  void ApplyGraph();

  SlamConfig config_;
  FlirtExtractor extractor_;
  ScanOdometry odometry_;
  LocalMapper mapper_;
  PoseGraph graph_;
  GlobalMap map_;
  std::vector<Pose2> icp_origins_;  // ICP T_world_robot of each submap's origin
  std::vector<std::vector<Pose2>> icp_submap_poses_;
  std::vector<double> origin_path_m_;             // travelled path at each submap origin
  std::vector<SubmapCloud> clouds_;               // one per completed submap (loop refinement)
  std::vector<OccupancySummary> observed_areas_;  // one per completed submap
  // Endpoints (robot frame, range-filtered) of the scans of the submap in progress.
  std::vector<std::vector<Eigen::Vector2d>> pending_points_;
  // The keypoints (robot frame) of the scans of the submap in progress: the loop query uses all
  // of them, as `keyplace localize` does, when place.query_keypoints is all_scans (issue 17).
  struct ScanKeypoints {
    std::vector<Eigen::Vector2d> positions_robot;
    std::vector<BetaGridDescriptor> descriptors;
  };
  std::vector<ScanKeypoints> pending_keypoints_;
  std::vector<Place> places_;  // one per completed submap (place frame = submap frame)
  std::unique_ptr<PlaceRecognizer> recognizer_;  // the eligible prefix of places_
  std::vector<LoopClosure> loops_;
  int loops_since_optimization_ = 0;
  bool dirty_ = false;  // loops added since the last optimisation

  struct ScanRecord {
    int scan_index = 0;
    double timestamp_s = 0.0;
    Pose2 icp;
    int submap = -1;
  };
  ScanPose PoseOf(const ScanRecord& record) const;

  std::vector<ScanRecord> scans_;
  std::size_t first_pending_scan_ = 0;  // scans_ from here belong to the submap in progress
  double path_m_ = 0.0;
  bool have_previous_ = false;
  Pose2 previous_icp_;
  SlamStats stats_;
};

}  // namespace keyplace
