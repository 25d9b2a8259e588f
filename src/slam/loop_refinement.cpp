#include "keyplace/slam/loop_refinement.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace keyplace {
namespace {

std::uint64_t VoxelKey(const Eigen::Vector2d& p, double voxel_m) {
  const auto i = static_cast<std::int64_t>(std::floor(p.x() / voxel_m));
  const auto j = static_cast<std::int64_t>(std::floor(p.y() / voxel_m));
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
         static_cast<std::uint32_t>(j);
}

double Overlap(const IcpTarget& a, const SubmapCloud& a_cloud, const IcpTarget& b,
               const SubmapCloud& b_cloud, const Pose2& T_a_b, const IcpConfig& icp) {
  const std::size_t total = a_cloud.points.size() + b_cloud.points.size();
  if (total == 0) return 0.0;
  const int b_in_a = CountIcpInliers(a, b_cloud.points, T_a_b, icp).count;
  const int a_in_b = CountIcpInliers(b, a_cloud.points, T_a_b.inverse(), icp).count;
  return static_cast<double>(b_in_a + a_in_b) / static_cast<double>(total);
}

}  // namespace

IcpConfig DefaultLoopIcpConfig() {
  IcpConfig icp;
  icp.max_correspondence_distance_m = 0.3;
  icp.inlier_distance_m = 0.05;
  icp.kernel = RobustKernel::kCauchy;
  icp.kernel_scale_m = 0.1;
  icp.max_iterations = 30;
  icp.min_inliers = 20;
  icp.min_inlier_ratio = 0.25;
  return icp;
}

void Validate(const LoopRefinementConfig& config) {
  ValidateIcpConfig(config.icp);
  auto fail = [](const std::string& field, const std::string& why) {
    throw std::invalid_argument("LoopRefinementConfig." + field + ": " + why);
  };
  if (!(config.max_correction_m >= 0.0)) fail("max_correction_m", "must be >= 0");
  if (!(config.max_correction_rad >= 0.0)) fail("max_correction_rad", "must be >= 0");
  if (!(config.max_inlier_ratio_loss >= 0.0 && config.max_inlier_ratio_loss <= 1.0)) {
    fail("max_inlier_ratio_loss", "must be in [0, 1]");
  }
  if (config.partner_neighbours < 0) fail("partner_neighbours", "must be >= 0");
  if (!(config.min_point_overlap >= 0.0 && config.min_point_overlap <= 1.0)) {
    fail("min_point_overlap", "must be in [0, 1]");
  }
  if (!(config.voxel_m > 0.0)) fail("voxel_m", "must be > 0");
  if (!(config.min_range_m >= 0.0)) fail("min_range_m", "must be >= 0");
  if (!(config.max_range_m > config.min_range_m)) fail("max_range_m", "must be > min_range_m");
}

SubmapCloud BuildSubmapCloud(const std::vector<std::vector<Eigen::Vector2d>>& scan_points_laser,
                             const std::vector<Pose2>& T_submap_laser,
                             const LoopRefinementConfig& config) {
  if (scan_points_laser.size() != T_submap_laser.size()) {
    throw std::invalid_argument("BuildSubmapCloud: one laser pose per scan expected");
  }
  if (!(config.voxel_m > 0.0)) {
    throw std::invalid_argument("LoopRefinementConfig.voxel_m: must be > 0");
  }
  struct Voxel {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int count = 0;
  };
  std::vector<Voxel> voxels;
  std::unordered_map<std::uint64_t, std::size_t> index;
  for (std::size_t s = 0; s < scan_points_laser.size(); ++s) {
    for (const Eigen::Vector2d& p_laser : scan_points_laser[s]) {
      const Eigen::Vector2d p = T_submap_laser[s] * p_laser;
      const auto [it, inserted] = index.emplace(VoxelKey(p, config.voxel_m), voxels.size());
      if (inserted) voxels.emplace_back();
      Voxel& voxel = voxels[it->second];
      voxel.sum += p;
      ++voxel.count;
    }
  }
  SubmapCloud cloud;
  cloud.points.reserve(voxels.size());
  for (const Voxel& voxel : voxels) cloud.points.push_back(voxel.sum / voxel.count);
  cloud.normals = EstimateNormals(cloud.points, config.icp);
  return cloud;
}

double PointOverlap(const SubmapCloud& a, const SubmapCloud& b, const Pose2& T_a_b,
                    const IcpConfig& icp) {
  if (a.points.empty() || b.points.empty()) return 0.0;
  const IcpTarget target_a(a.points, a.normals, icp);
  const IcpTarget target_b(b.points, b.normals, icp);
  return Overlap(target_a, a, target_b, b, T_a_b, icp);
}

namespace {

// RefineLoop with the current submap's target built by the caller, who refines one current
// submap against several references (ChooseLoopPartner) and builds it once.
LoopRefinement RefineLoopAgainst(const SubmapCloud& reference, const SubmapCloud& current,
                                 const IcpTarget& target_cur, const Pose2& T_ref_cur_initial,
                                 const LoopRefinementConfig& config) {
  LoopRefinement result;
  result.T_ref_cur = T_ref_cur_initial;
  if (reference.points.empty() || current.points.empty()) return result;
  const IcpTarget target_ref(reference.points, reference.normals, config.icp);
  const double n_cur = static_cast<double>(current.points.size());
  result.inlier_ratio_initial =
      CountIcpInliers(target_ref, current.points, T_ref_cur_initial, config.icp).count / n_cur;
  result.inlier_ratio = result.inlier_ratio_initial;
  if (config.refine) {
    const IcpResult icp =
        AlignPointToLine(target_ref, current.points, T_ref_cur_initial, config.icp);
    result.status = icp.status;
    result.iterations = icp.iterations;
    const Pose2 correction = Between(T_ref_cur_initial, icp.T_target_source);
    if (icp.converged && TranslationNorm(correction) <= config.max_correction_m &&
        std::abs(correction.theta) <= config.max_correction_rad &&
        icp.inlier_ratio >= result.inlier_ratio_initial - config.max_inlier_ratio_loss) {
      result.refined = true;
      result.T_ref_cur = icp.T_target_source;
      result.inlier_ratio = icp.inlier_ratio;
      result.correction_m = TranslationNorm(correction);
      result.correction_rad = std::abs(correction.theta);
    }
  }
  result.overlap =
      Overlap(target_ref, reference, target_cur, current, result.T_ref_cur, config.icp);
  return result;
}

}  // namespace

LoopRefinement RefineLoop(const SubmapCloud& reference, const SubmapCloud& current,
                          const Pose2& T_ref_cur_initial, const LoopRefinementConfig& config) {
  Validate(config);
  if (reference.points.empty() || current.points.empty()) {
    LoopRefinement result;
    result.T_ref_cur = T_ref_cur_initial;
    return result;
  }
  const IcpTarget target_cur(current.points, current.normals, config.icp);
  return RefineLoopAgainst(reference, current, target_cur, T_ref_cur_initial, config);
}

LoopPartnerChoice ChooseLoopPartner(const SubmapCloud& current, int matched_id,
                                    const SubmapCloud& matched, const Pose2& T_matched_cur_initial,
                                    const std::vector<LoopPartnerCandidate>& candidates,
                                    const LoopRefinementConfig& config) {
  Validate(config);
  const IcpTarget target_cur(current.points, current.normals, config.icp);
  LoopPartnerChoice choice;
  choice.partner = matched_id;
  choice.refinement =
      RefineLoopAgainst(matched, current, target_cur, T_matched_cur_initial, config);
  const Pose2 T_matched_cur = choice.refinement.T_ref_cur;
  for (const LoopPartnerCandidate& candidate : candidates) {
    if (candidate.cloud == nullptr) {
      throw std::invalid_argument("ChooseLoopPartner: candidate " + std::to_string(candidate.id) +
                                  " has no cloud");
    }
    LoopRefinement r = RefineLoopAgainst(*candidate.cloud, current, target_cur,
                                         candidate.T_candidate_matched * T_matched_cur, config);
    if (r.overlap > choice.refinement.overlap) {
      choice.partner = candidate.id;
      choice.refinement = r;
    }
  }
  return choice;
}

}  // namespace keyplace
