#include "keyplace/mapping/mapping_config.hpp"

#include <stdexcept>
#include <string>

#include "keyplace/common/config_fields.hpp"

namespace keyplace {
namespace {

void Require(bool ok, const std::string& field, const std::string& rule) {
  if (!ok) throw std::invalid_argument("MappingConfig." + field + " " + rule);
}

}  // namespace

void Validate(const MappingConfig& config) {
  Require(config.cell_size_m > 0.0, "cell_size_m", "must be positive");
  Require(config.min_stability >= 0.0, "min_stability", "must be >= 0");
  Require(config.min_scan_count >= 1, "min_scan_count", "must be >= 1");
  Require(config.descriptor_match_chi2 > 0.0, "descriptor_match_chi2", "must be positive");
  Require(config.min_overlap >= 0.0 && config.min_overlap <= 1.0, "min_overlap",
          "must lie in [0, 1]");
  Require(config.max_distribution >= 0.0, "max_distribution", "must be >= 0");
  Require(config.distribution_cell_m > 0.0, "distribution_cell_m", "must be positive");
  Require(config.min_stable_keypoints >= 0, "min_stable_keypoints", "must be >= 0");
  Require(config.max_scans_per_submap >= 0, "max_scans_per_submap", "must be >= 0");
}

}  // namespace keyplace

namespace keyplace {
namespace {

const ConfigFields<MappingConfig>& Fields() {
  using C = MappingConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("MappingConfig");
    table.Double("cell_size_m", &C::cell_size_m)
        .Double("min_stability", &C::min_stability)
        .Int("min_scan_count", &C::min_scan_count)
        .Double("descriptor_match_chi2", &C::descriptor_match_chi2)
        .Enum("density_counting", &C::density_counting,
              {{C::DensityCounting::kScans, "scans"}, {C::DensityCounting::kBeams, "beams"}})
        .Enum("cluster_match", &C::cluster_match,
              {{C::ClusterMatch::kAnyMember, "any_member"},
               {C::ClusterMatch::kLatestMember, "latest_member"}})
        .Double("min_overlap", &C::min_overlap)
        .Enum("overlap_cells", &C::overlap_cells,
              {{C::OverlapCells::kHit, "hit"}, {C::OverlapCells::kObserved, "observed"}})
        .Bool("use_distribution", &C::use_distribution)
        .Double("max_distribution", &C::max_distribution)
        .Double("distribution_cell_m", &C::distribution_cell_m)
        .Enum("distribution_laser_cells", &C::distribution_laser_cells,
              {{C::LaserCells::kHit, "hit"},
               {C::LaserCells::kOccupied, "occupied"},
               {C::LaserCells::kPersistent, "persistent"}})
        .Enum("distribution_normalization", &C::distribution_normalization,
              {{C::DistributionNormalization::kPoints, "points"},
               {C::DistributionNormalization::kCells, "cells"}})
        .Int("min_stable_keypoints", &C::min_stable_keypoints)
        .Int("max_scans_per_submap", &C::max_scans_per_submap);
    return table;
  }();
  return fields;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> ToKeyValues(const MappingConfig& config) {
  return Fields().ToKeyValues(config);
}

void ApplyKeyValues(const std::map<std::string, std::string>& values, MappingConfig& config) {
  Fields().Apply(values, config);
  Validate(config);
}

}  // namespace keyplace
