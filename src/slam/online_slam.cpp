#include "keyplace/slam/online_slam.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/seconds_since.hpp"

namespace keyplace {
namespace {}  // namespace

void Validate(const SlamConfig& config) {
  ValidateScanOdometryConfig(config.odometry);
  Validate(config.mapping);
  Validate(config.place);
  Validate(config.graph);
  Validate(config.loop_refinement);
  auto fail = [](const std::string& field, const std::string& why) {
    throw std::invalid_argument("SlamConfig." + field + ": " + why);
  };
  if (config.exclude_recent_submaps < 0) fail("exclude_recent_submaps", "must be >= 0");
  if (!(config.exclude_recent_path_m >= 0.0)) fail("exclude_recent_path_m", "must be >= 0");
  if (!(config.loop_search_near_m >= 0.0) || !std::isfinite(config.loop_search_near_m)) {
    fail("loop_search_near_m", "must be finite and >= 0");
  }
  if (!(config.gate_base_m >= 0.0)) fail("gate_base_m", "must be >= 0");
  if (!(config.gate_per_path >= 0.0)) fail("gate_per_path", "must be >= 0");
  if (!(config.gate_base_rad >= 0.0)) fail("gate_base_rad", "must be >= 0");
  if (!(config.gate_per_path_rad >= 0.0)) fail("gate_per_path_rad", "must be >= 0");
  if (!(config.odometry_sigma_base_m > 0.0)) fail("odometry_sigma_base_m", "must be > 0");
  if (!(config.odometry_sigma_per_m >= 0.0)) fail("odometry_sigma_per_m", "must be >= 0");
  if (!(config.odometry_sigma_base_rad > 0.0)) fail("odometry_sigma_base_rad", "must be > 0");
  if (!(config.odometry_sigma_per_rad >= 0.0)) fail("odometry_sigma_per_rad", "must be >= 0");
  if (!(config.odometry_sigma_rad_per_m >= 0.0)) fail("odometry_sigma_rad_per_m", "must be >= 0");
  if (!(config.loop_sigma_m > 0.0)) fail("loop_sigma_m", "must be > 0");
  if (!(config.loop_sigma_rad > 0.0)) fail("loop_sigma_rad", "must be > 0");
  if (config.loop_reference_consensus < 1) fail("loop_reference_consensus", "must be >= 1");
  if (config.optimize_every_loops < 1) fail("optimize_every_loops", "must be >= 1");
  if (!(config.defer_loop_residual_sigmas >= 0.0 &&
        std::isfinite(config.defer_loop_residual_sigmas))) {
    fail("defer_loop_residual_sigmas", "must be >= 0 and finite");
  }
}

OnlineSlam::OnlineSlam(const SlamConfig& config, const FlirtConfig& features)
    : config_(config), extractor_(features), odometry_(config.odometry), mapper_(config.mapping) {
  Validate(config_);
  // Loop queries come once per submap and overlapping submaps follow each other: on Intel_r and
  // FR079_r the loops retrieval misses changed neither relation error (docs/SLAM.md, "Retrieval").
  if (config_.place.retrieval == PlaceRecognitionConfig::Retrieval::kAuto) {
    config_.place.retrieval = PlaceRecognitionConfig::Retrieval::kWords;
  }
  map_.config = config_.mapping;
  map_.pose_source = "slam";
}

OnlineSlam::~OnlineSlam() = default;

bool OnlineSlam::QueriesWithAllScans() const {
  return config_.all_scan_loop_queries &&
         config_.place.query_keypoints == PlaceRecognitionConfig::QueryKeypoints::kAllScans;
}

SlamStep OnlineSlam::AddScan(int scan_index, const LaserScan& scan,
                             const std::optional<Pose2>& T_odom_robot) {
  const Pose2 T_odom_laser = T_odom_robot.value_or(Pose2()) * scan.T_robot_laser;
  return AddScan(scan_index, scan, T_odom_robot, extractor_.Extract(scan, T_odom_laser));
}

SlamStep OnlineSlam::AddScan(int scan_index, const LaserScan& scan,
                             const std::optional<Pose2>& T_odom_robot,
                             const std::vector<Keypoint>& keypoints) {
  SlamStep step;
  auto start = std::chrono::steady_clock::now();
  step.odometry = odometry_.Add(scan, T_odom_robot);
  const Pose2& pose = step.odometry.T_world_robot;
  if (have_previous_) path_m_ += (pose.translation() - previous_icp_.translation()).norm();
  previous_icp_ = pose;
  have_previous_ = true;
  scans_.push_back({scan_index, scan.timestamp_s, pose, -1});
  std::vector<Eigen::Vector2d> points;
  points.reserve(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double range = scan.ranges_m[i];
    if (scan.valid[i] == 0 || range < config_.loop_refinement.min_range_m ||
        range >= config_.loop_refinement.max_range_m) {
      continue;
    }
    points.push_back(scan.T_robot_laser * scan.Endpoint(i));
  }
  pending_points_.push_back(std::move(points));
  ScanKeypoints scan_keypoints;
  if (QueriesWithAllScans()) {
    scan_keypoints.positions_robot.reserve(keypoints.size());
    scan_keypoints.descriptors.reserve(keypoints.size());
    for (const Keypoint& keypoint : keypoints) {
      scan_keypoints.positions_robot.push_back(scan.T_robot_laser * keypoint.position_m);
      scan_keypoints.descriptors.push_back(keypoint.descriptor);
    }
  }
  pending_keypoints_.push_back(std::move(scan_keypoints));
  ++stats_.scans;
  map_.source_scans = stats_.scans;
  map_.source_keypoints += keypoints.size();
  stats_.seconds_odometry += SecondsSince(start);

  start = std::chrono::steady_clock::now();
  bool complete = false;
  try {
    complete = mapper_.AddScan(scan_index, scan, pose, keypoints);
  } catch (...) {
    // The mapper is as it was (it checks before it changes anything): so is the submap in
    // progress, and a caller that goes on (a robot node) maps on with the next scan.
    scans_.pop_back();
    pending_points_.pop_back();
    pending_keypoints_.pop_back();
    --stats_.scans;
    map_.source_scans = stats_.scans;
    map_.source_keypoints -= keypoints.size();
    throw;
  }
  stats_.seconds_mapping += SecondsSince(start);
  if (complete) CompleteSubmap(step);
  return step;
}

void OnlineSlam::CompleteSubmap(SlamStep& step) {
  auto start = std::chrono::steady_clock::now();
  Submap submap = mapper_.Snapshot();
  {
    OccupancySummary observed;
    observed.cell_size_m = mapper_.grid().cell_size_m();
    const std::vector<CellIndex> cells = mapper_.grid().ObservedCells();
    observed.cells.reserve(cells.size());
    for (const CellIndex& cell : cells) observed.cells.emplace_back(cell.i, cell.j);
    observed_areas_.push_back(std::move(observed));
  }
  mapper_.Reset();
  const int id = static_cast<int>(map_.submaps.size());
  submap.id = id;
  const std::size_t n_scans = submap.poses.size();
  for (std::size_t k = first_pending_scan_; k < scans_.size(); ++k) scans_[k].submap = id;
  first_pending_scan_ = scans_.size();
  // The path at the submap origin: path now minus the path of its scans after the first.
  double path_inside = 0.0;
  for (std::size_t k = 1; k < n_scans; ++k) {
    path_inside += (submap.poses[k].translation() - submap.poses[k - 1].translation()).norm();
  }
  const double origin_path = path_m_ - path_inside;
  const Pose2 icp_origin = submap.origin();

  // Graph node, initialised through the previous node's corrected pose.
  if (id == 0) {
    graph_.AddNode(icp_origin);
  } else {
    const Pose2 T_prev_cur = Between(icp_origins_.back(), icp_origin);
    graph_.AddNode(graph_.node(id - 1) * T_prev_cur);
    PoseGraphEdge edge;
    edge.kind = PoseGraphEdge::Kind::kOdometry;
    edge.from = id - 1;
    edge.to = id;
    edge.T_from_to = T_prev_cur;
    const double d = TranslationNorm(T_prev_cur);
    const double a = std::abs(T_prev_cur.theta);
    edge.sigma_x_m = edge.sigma_y_m =
        config_.odometry_sigma_base_m + config_.odometry_sigma_per_m * d;
    edge.sigma_theta_rad = config_.odometry_sigma_base_rad + config_.odometry_sigma_per_rad * a +
                           config_.odometry_sigma_rad_per_m * d;
    graph_.AddEdge(edge);
  }
  icp_origins_.push_back(icp_origin);
  icp_submap_poses_.push_back(submap.poses);
  origin_path_m_.push_back(origin_path);
  PlaceQuery query;
  {
    std::vector<Pose2> T_submap_robot;
    T_submap_robot.reserve(submap.poses.size());
    for (const Pose2& p : submap.poses) T_submap_robot.push_back(Between(icp_origin, p));
    clouds_.push_back(BuildSubmapCloud(pending_points_, T_submap_robot, config_.loop_refinement));
    pending_points_.clear();
    // Every keypoint of every scan in the submap frame, latest scans first (as MakeSubmapQuery),
    // so that merging nearby keypoints keeps the latest.
    for (std::size_t k = pending_keypoints_.size(); k-- > 0;) {
      const ScanKeypoints& scan = pending_keypoints_[k];
      for (std::size_t i = 0; i < scan.positions_robot.size(); ++i) {
        query.all_positions.push_back(T_submap_robot.at(k) * scan.positions_robot[i]);
        query.all_descriptors.push_back(scan.descriptors[i]);
      }
    }
    pending_keypoints_.clear();
  }
  // The submap's poses follow its (possibly corrected) node.
  const Pose2 node = graph_.node(id);
  for (Pose2& p : submap.poses) p = node * Between(icp_origin, p);

  Place place;
  place.id = id;
  place.T_world_place = node;
  place.scan_indices = submap.scan_indices;
  for (const StableKeypoint& keypoint : submap.keypoints) {
    place.positions.push_back(keypoint.position_m);
    place.descriptors.push_back(keypoint.descriptor);
  }
  query.positions = place.positions;
  query.descriptors = place.descriptors;
  query.T_first_evaluated = Between(submap.poses.front(), submap.poses.back());
  map_.submaps.push_back(std::move(submap));
  places_.push_back(std::move(place));
  ++stats_.submaps;
  step.submap_completed = true;
  step.submap_id = id;
  stats_.seconds_mapping += SecondsSince(start);

  // Eligible places: a prefix of the map (path grows with the submap index).
  start = std::chrono::steady_clock::now();
  std::size_t eligible = 0;
  while (eligible < places_.size() &&
         static_cast<int>(eligible) + config_.exclude_recent_submaps < id &&
         origin_path_m_[eligible] + config_.exclude_recent_path_m <= origin_path) {
    ++eligible;
  }
  if (eligible > 0) {
    if (!recognizer_)
      recognizer_ = std::make_unique<PlaceRecognizer>(std::vector<Place>{}, config_.place);
    if (recognizer_->places().size() != eligible) {
      // The recognizer holds the eligible prefix; it only grows (eligibility depends on the id and
      // the path, both growing), so each submap is indexed once. Held places take the graph poses
      // of now, as a recognizer built anew from the prefix would (a pose changes no descriptor).
      const std::size_t held = recognizer_->places().size();
      for (std::size_t i = 0; i < held; ++i) {
        recognizer_->SetPlacePose(i, places_[i].T_world_place);
      }
      for (std::size_t i = held; i < eligible; ++i) recognizer_->AddPlace(places_[i]);
    }
    ++stats_.queries;
    query.also_search_ids = PlaceIdsToAlsoSearch(config_.place, query.by_words, places_, eligible,
                                                 places_.back().T_world_place.translation(),
                                                 config_.loop_search_near_m);
    step.match = recognizer_->Recognize(query);
    if (step.match.found) {
      LoopClosure loop;
      loop.query_submap = id;
      loop.matched_submap = step.match.place_id;
      loop.T_matched_cur_ransac = step.match.T_ref_cur;
      loop.pairs = step.match.pairs;
      loop.consensus = step.match.consensus;
      loop.gamma = step.match.gamma;
      loop.confidence = step.match.confidence;
      const auto refine_start = std::chrono::steady_clock::now();
      RefineAndChoosePartner(id, eligible, loop);
      stats_.seconds_loop_refinement += SecondsSince(refine_start);
      if (loop.point_overlap < config_.loop_refinement.min_point_overlap) {
        ++stats_.loops_rejected_by_point_overlap;
      } else {
        AddLoop(id, origin_path, loop);
        step.loop = static_cast<int>(loops_.size()) - 1;
      }
    }
  }
  stats_.seconds_recognition += SecondsSince(start);

  if (loops_since_optimization_ >= config_.optimize_every_loops) {
    Optimize();
    step.optimized = true;
  }
}

void OnlineSlam::RefineAndChoosePartner(int id, std::size_t eligible, LoopClosure& loop) {
  const LoopRefinementConfig& config = config_.loop_refinement;
  const int matched = loop.matched_submap;
  // Neighbours of the matched submap, nearest first, before and after it; eligible places only
  // (never a recent neighbour of the current submap). The initial transform to a neighbour goes
  // through the graph estimate of the two neighbours (odometry-accurate at this distance).
  std::vector<LoopPartnerCandidate> candidates;
  for (int offset = 1; offset <= config.partner_neighbours; ++offset) {
    for (const int candidate : {matched - offset, matched + offset}) {
      if (candidate < 0 || candidate >= static_cast<int>(eligible)) continue;
      candidates.push_back({candidate, &clouds_[static_cast<std::size_t>(candidate)],
                            Between(graph_.node(candidate), graph_.node(matched))});
    }
  }
  const LoopPartnerChoice choice = ChooseLoopPartner(clouds_[static_cast<std::size_t>(id)], matched,
                                                     clouds_[static_cast<std::size_t>(matched)],
                                                     loop.T_matched_cur_ransac, candidates, config);
  const LoopRefinement& best = choice.refinement;
  loop.reference_submap = choice.partner;
  loop.T_ref_cur = best.T_ref_cur;
  loop.refined = best.refined;
  loop.refine_status = best.status;
  loop.refine_inlier_ratio_initial = best.inlier_ratio_initial;
  loop.refine_inlier_ratio = best.inlier_ratio;
  loop.refine_correction_m = best.correction_m;
  loop.refine_correction_rad = best.correction_rad;
  loop.point_overlap = best.overlap;
}

void OnlineSlam::AddLoop(int id, double origin_path, LoopClosure loop) {
  loop.path_between_m = origin_path - origin_path_m_[loop.reference_submap];
  const Pose2 predicted = Between(graph_.node(loop.reference_submap), graph_.node(id));
  const Pose2 disagreement = Between(predicted, loop.T_ref_cur);
  loop.gate_translation_m = TranslationNorm(disagreement);
  loop.gate_rotation_rad = std::abs(disagreement.theta);
  loop.accepted = config_.gate_base_m <= 0.0 ||
                  (loop.gate_translation_m <=
                       config_.gate_base_m + config_.gate_per_path * loop.path_between_m &&
                   loop.gate_rotation_rad <=
                       config_.gate_base_rad + config_.gate_per_path_rad * loop.path_between_m);
  ++stats_.loops_detected;
  if (loop.accepted) {
    PoseGraphEdge edge;
    edge.kind = PoseGraphEdge::Kind::kLoop;
    edge.from = loop.reference_submap;
    edge.to = id;
    edge.T_from_to = loop.T_ref_cur;
    const double scale = std::sqrt(static_cast<double>(config_.loop_reference_consensus) /
                                   std::max(1, loop.consensus));
    edge.sigma_x_m = edge.sigma_y_m = config_.loop_sigma_m * scale;
    edge.sigma_theta_rad = config_.loop_sigma_rad * scale;
    loop.edge = graph_.AddEdge(edge);
    ++stats_.loops_accepted;
    dirty_ = true;
    // A loop the estimate already meets within its own sigmas would move it by less than its
    // noise: it waits (in the graph) for the next loop that disagrees, or for Finish().
    if (graph_.WhitenedResidual(loop.edge) > config_.defer_loop_residual_sigmas) {
      ++loops_since_optimization_;
    } else {
      ++stats_.loops_deferred;
    }
  }
  stats_.loops_refined += loop.refined ? 1 : 0;
  stats_.loops_partner_changed += loop.reference_submap != loop.matched_submap ? 1 : 0;
  loops_.push_back(loop);
}

void OnlineSlam::Optimize() {
  const auto start = std::chrono::steady_clock::now();
  const PoseGraphResult result = graph_.Optimize(config_.graph);
  ++stats_.optimizations;
  stats_.solves += static_cast<std::size_t>(result.solves);
  loops_since_optimization_ = 0;
  dirty_ = false;
  ApplyGraph();
  std::size_t rejected = 0;
  for (const LoopClosure& loop : loops_) rejected += (loop.accepted && !LoopUsed(loop)) ? 1 : 0;
  stats_.loops_rejected_by_graph = rejected;
  stats_.seconds_optimization += SecondsSince(start);
}

void OnlineSlam::ApplyGraph() {
  for (std::size_t i = 0; i < map_.submaps.size(); ++i) {
    const Pose2 node = graph_.node(static_cast<int>(i));
    const std::vector<Pose2>& icp = icp_submap_poses_[i];
    std::vector<Pose2>& poses = map_.submaps[i].poses;
    for (std::size_t k = 0; k < poses.size(); ++k) poses[k] = node * Between(icp.front(), icp[k]);
    places_[i].T_world_place = node;
  }
}

void OnlineSlam::Finish() {
  if (dirty_) Optimize();
}

bool OnlineSlam::LoopUsed(const LoopClosure& loop) const {
  return loop.accepted && loop.edge >= 0 && graph_.active(loop.edge);
}

std::vector<OnlineSlam::ScanPose> OnlineSlam::Trajectory() const {
  std::vector<ScanPose> trajectory;
  trajectory.reserve(scans_.size());
  for (const ScanRecord& record : scans_) trajectory.push_back(PoseOf(record));
  return trajectory;
}

OnlineSlam::ScanPose OnlineSlam::LatestPose() const {
  return scans_.empty() ? ScanPose{} : PoseOf(scans_.back());
}

OnlineSlam::ScanPose OnlineSlam::PoseOf(const ScanRecord& record) const {
  ScanPose pose;
  pose.scan_index = record.scan_index;
  pose.timestamp_s = record.timestamp_s;
  pose.T_world_robot_icp = record.icp;
  pose.submap = record.submap;
  const int last = static_cast<int>(map_.submaps.size()) - 1;
  const int anchor = record.submap >= 0 ? record.submap : last;
  pose.T_world_robot =
      anchor >= 0 ? graph_.node(anchor) * Between(icp_origins_[anchor], record.icp) : record.icp;
  return pose;
}

}  // namespace keyplace
