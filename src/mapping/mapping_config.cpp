#include "keyplace/mapping/mapping_config.hpp"

#include <charconv>
#include <stdexcept>
#include <string>

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

// The shortest text that reads back as the same double.
std::string FormatDouble(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

double ParseDouble(const std::string& key, const std::string& text) {
  try {
    std::size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("MappingConfig." + key + ": '" + text + "' is not a number");
}

int ParseInt(const std::string& key, const std::string& text) {
  try {
    std::size_t used = 0;
    const int value = std::stoi(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("MappingConfig." + key + ": '" + text + "' is not an integer");
}

bool ParseBool(const std::string& key, const std::string& text) {
  if (text == "true" || text == "1") return true;
  if (text == "false" || text == "0") return false;
  throw std::invalid_argument("MappingConfig." + key + ": '" + text + "' is not true/false");
}

}  // namespace

std::vector<std::pair<std::string, std::string>> ToKeyValues(const MappingConfig& c) {
  using ClusterMatch = MappingConfig::ClusterMatch;
  using OverlapCells = MappingConfig::OverlapCells;
  return {
      {"cell_size_m", FormatDouble(c.cell_size_m)},
      {"min_stability", FormatDouble(c.min_stability)},
      {"min_scan_count", std::to_string(c.min_scan_count)},
      {"descriptor_match_chi2", FormatDouble(c.descriptor_match_chi2)},
      {"density_counting",
       c.density_counting == MappingConfig::DensityCounting::kScans ? "scans" : "beams"},
      {"cluster_match",
       c.cluster_match == ClusterMatch::kAnyMember ? "any_member" : "latest_member"},
      {"min_overlap", FormatDouble(c.min_overlap)},
      {"overlap_cells", c.overlap_cells == OverlapCells::kHit ? "hit" : "observed"},
      {"use_distribution", c.use_distribution ? "true" : "false"},
      {"max_distribution", FormatDouble(c.max_distribution)},
      {"distribution_cell_m", FormatDouble(c.distribution_cell_m)},
      {"distribution_laser_cells",
       c.distribution_laser_cells == MappingConfig::LaserCells::kHit        ? "hit"
       : c.distribution_laser_cells == MappingConfig::LaserCells::kOccupied ? "occupied"
                                                                            : "persistent"},
      {"distribution_normalization",
       c.distribution_normalization == MappingConfig::DistributionNormalization::kPoints ? "points"
                                                                                         : "cells"},
      {"min_stable_keypoints", std::to_string(c.min_stable_keypoints)},
      {"max_scans_per_submap", std::to_string(c.max_scans_per_submap)},
  };
}

void ApplyKeyValues(const std::map<std::string, std::string>& values, MappingConfig& c) {
  for (const auto& [key, text] : values) {
    if (key == "cell_size_m") {
      c.cell_size_m = ParseDouble(key, text);
    } else if (key == "min_stability") {
      c.min_stability = ParseDouble(key, text);
    } else if (key == "min_scan_count") {
      c.min_scan_count = ParseInt(key, text);
    } else if (key == "descriptor_match_chi2") {
      c.descriptor_match_chi2 = ParseDouble(key, text);
    } else if (key == "density_counting") {
      if (text == "scans") {
        c.density_counting = MappingConfig::DensityCounting::kScans;
      } else if (text == "beams") {
        c.density_counting = MappingConfig::DensityCounting::kBeams;
      } else {
        throw std::invalid_argument("MappingConfig.density_counting: '" + text +
                                    "' is not scans or beams");
      }
    } else if (key == "cluster_match") {
      if (text == "any_member") {
        c.cluster_match = MappingConfig::ClusterMatch::kAnyMember;
      } else if (text == "latest_member") {
        c.cluster_match = MappingConfig::ClusterMatch::kLatestMember;
      } else {
        throw std::invalid_argument("MappingConfig.cluster_match: '" + text +
                                    "' is not any_member or latest_member");
      }
    } else if (key == "min_overlap") {
      c.min_overlap = ParseDouble(key, text);
    } else if (key == "overlap_cells") {
      if (text == "hit") {
        c.overlap_cells = MappingConfig::OverlapCells::kHit;
      } else if (text == "observed") {
        c.overlap_cells = MappingConfig::OverlapCells::kObserved;
      } else {
        throw std::invalid_argument("MappingConfig.overlap_cells: '" + text +
                                    "' is not hit or observed");
      }
    } else if (key == "use_distribution") {
      c.use_distribution = ParseBool(key, text);
    } else if (key == "max_distribution") {
      c.max_distribution = ParseDouble(key, text);
    } else if (key == "distribution_cell_m") {
      c.distribution_cell_m = ParseDouble(key, text);
    } else if (key == "distribution_laser_cells") {
      if (text == "hit") {
        c.distribution_laser_cells = MappingConfig::LaserCells::kHit;
      } else if (text == "occupied") {
        c.distribution_laser_cells = MappingConfig::LaserCells::kOccupied;
      } else if (text == "persistent") {
        c.distribution_laser_cells = MappingConfig::LaserCells::kPersistent;
      } else {
        throw std::invalid_argument("MappingConfig.distribution_laser_cells: '" + text +
                                    "' is not hit, occupied or persistent");
      }
    } else if (key == "distribution_normalization") {
      if (text == "points") {
        c.distribution_normalization = MappingConfig::DistributionNormalization::kPoints;
      } else if (text == "cells") {
        c.distribution_normalization = MappingConfig::DistributionNormalization::kCells;
      } else {
        throw std::invalid_argument("MappingConfig.distribution_normalization: '" + text +
                                    "' is not points or cells");
      }
    } else if (key == "min_stable_keypoints") {
      c.min_stable_keypoints = ParseInt(key, text);
    } else if (key == "max_scans_per_submap") {
      c.max_scans_per_submap = ParseInt(key, text);
    } else {
      throw std::invalid_argument("MappingConfig: unknown key '" + key + "'");
    }
  }
  Validate(c);
}

}  // namespace keyplace
