#include "keyplace/mapping/mapping_config.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/config_fields.hpp"
#include "mapping/mapping_fields.hpp"

namespace keyplace {
namespace {

void Require(bool ok, const std::string& field, const std::string& rule) {
  if (!ok) throw std::invalid_argument("MappingConfig." + field + " " + rule);
}

}  // namespace

void Validate(const MappingConfig& config) {
  // Written so that NaN fails every comparison; isfinite for the fields without an upper bound.
  Require(config.cell_size_m >= kMinCellSizeM && config.cell_size_m <= kMaxCellSizeM, "cell_size_m",
          "must lie in [0.01, 10] m (docs/MAPPING.md)");
  Require(std::isfinite(config.min_stability) && config.min_stability >= 0.0, "min_stability",
          "must be finite and >= 0");
  Require(config.min_scan_count >= 1, "min_scan_count", "must be >= 1");
  Require(std::isfinite(config.descriptor_match_chi2) && config.descriptor_match_chi2 > 0.0,
          "descriptor_match_chi2", "must be finite and positive");
  Require(config.min_overlap >= 0.0 && config.min_overlap <= 1.0, "min_overlap",
          "must lie in [0, 1]");
  Require(std::isfinite(config.max_distribution) && config.max_distribution >= 0.0,
          "max_distribution", "must be finite and >= 0");
  Require(config.distribution_cell_m >= kMinCellSizeM &&
              config.distribution_cell_m <= kMaxDistributionCellM,
          "distribution_cell_m", "must lie in [0.01, 100] m (docs/MAPPING.md)");
  Require(config.min_stable_keypoints >= 0, "min_stable_keypoints", "must be >= 0");
  Require(std::isfinite(config.max_path_m) && config.max_path_m >= 0.0, "max_path_m",
          "must be finite and >= 0 (0 = no bound)");
  Require(config.max_scans_per_submap >= 0, "max_scans_per_submap", "must be >= 0");
  Require(config.max_grid_cells >= 1 && config.max_grid_cells <= kMaxGridCellsLimit,
          "max_grid_cells", "must lie in [1, 2^28] (docs/MAPPING.md)");
}

}  // namespace keyplace

namespace keyplace {

const ConfigFields<MappingConfig>& MappingConfigFields() {
  using C = MappingConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("MappingConfig");
    table.Double("cell_size_m", &C::cell_size_m, "m", "l_g: side of a cell of the stability grid G")
        .Double("min_stability", &C::min_stability, "",
                "s_min: a cell's keypoint is stable when s >= s_min")
        .Int("min_scan_count", &C::min_scan_count, "", "ns_min: s = d * occ / max(ns, ns_min)")
        .Double("descriptor_match_chi2", &C::descriptor_match_chi2, "",
                "similar descriptors: symmetric chi2 below this")
        .Enum("density_counting", &C::density_counting,
              {{C::DensityCounting::kScans, "scans"}, {C::DensityCounting::kBeams, "beams"}},
              "h and m of the density d = h / (h + m) counted per scan or per beam")
        .Enum("cluster_match", &C::cluster_match,
              {{C::ClusterMatch::kAnyMember, "any_member"},
               {C::ClusterMatch::kLatestMember, "latest_member"}},
              "which member of a history cluster a new keypoint is compared with")
        .Double("min_overlap", &C::min_overlap, "",
                "rho_min: a submap is complete once rho = a_int / a_uni drops below")
        .Enum("overlap_cells", &C::overlap_cells,
              {{C::OverlapCells::kHit, "hit"}, {C::OverlapCells::kObserved, "observed"}},
              "cells of the binary occupancy grids of rho")
        .Bool("use_distribution", &C::use_distribution,
              "also require delta <= max_distribution to complete a submap")
        .Double("max_distribution", &C::max_distribution, "", "delta_max")
        .Double("distribution_cell_m", &C::distribution_cell_m, "m",
                "l: cell of the grid of the histograms of delta")
        .Enum("distribution_laser_cells", &C::distribution_laser_cells,
              {{C::LaserCells::kHit, "hit"},
               {C::LaserCells::kOccupied, "occupied"},
               {C::LaserCells::kPersistent, "persistent"}},
              "which cells of G are the laser points of delta")
        .Enum("distribution_normalization", &C::distribution_normalization,
              {{C::DistributionNormalization::kPoints, "points"},
               {C::DistributionNormalization::kCells, "cells"}},
              "what the binary histograms of delta are divided by")
        .Int("min_stable_keypoints", &C::min_stable_keypoints, "",
             "a complete submap holds at least this many stable keypoints")
        .Double("max_path_m", &C::max_path_m, "m",
                "a submap is also complete once its path length reaches this (0 = no bound)")
        .Int("max_scans_per_submap", &C::max_scans_per_submap, "",
             "close a submap after this many scans anyway (0 = never)")
        .Int("max_grid_cells", &C::max_grid_cells, "",
             "close a submap before a scan would grow its grid G beyond this many cells "
             "(20 bytes each)");
    return table;
  }();
  return fields;
}

std::vector<std::pair<std::string, std::string>> ToKeyValues(const MappingConfig& config) {
  return MappingConfigFields().ToKeyValues(config);
}

void ApplyKeyValues(const std::map<std::string, std::string>& values, MappingConfig& config) {
  MappingConfigFields().Apply(values, config);
  Validate(config);
}

void ApplyStoredKeyValues(const std::map<std::string, std::string>& values, MappingConfig& config) {
  if (values.count("max_path_m") == 0) config.max_path_m = 0.0;
  ApplyKeyValues(values, config);
}

}  // namespace keyplace
