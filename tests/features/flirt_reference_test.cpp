// Validation against FLIRTLib's own output (../shared/reference/flirtlib, see its README).

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/features/flirt.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

// One tab-separated table with a header row.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;

  int Column(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw std::runtime_error("no column " + name);
    return static_cast<int>(it - header.begin());
  }
};

Table ReadTable(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  Table table;
  std::string line;
  std::getline(in, line);
  {
    std::istringstream fields(line);
    std::string name;
    while (std::getline(fields, name, '\t')) table.header.push_back(name);
  }
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream fields(line);
    std::vector<double> row;
    std::string value;
    while (std::getline(fields, value, '\t')) row.push_back(std::stod(value));
    table.rows.push_back(std::move(row));
  }
  return table;
}

struct ReferenceKeypoint {
  Eigen::Vector2d position_laser_m;
  double theta_laser_rad = 0.0;
  int scale_level = 0;
  int beam = 0;
  BetaGridDescriptor descriptor{};
};

// Reference keypoints of the first scans, grouped by scan.
std::map<int, std::vector<ReferenceKeypoint>> ReadReference(const std::string& dataset) {
  const Table keypoints =
      ReadTable(testing::SharedFile("reference/flirtlib/" + dataset + "_first50_keypoints.tsv"));
  const Table descriptors =
      ReadTable(testing::SharedFile("reference/flirtlib/" + dataset + "_first50_descriptors.tsv"));
  const int c_scan = keypoints.Column("scan"), c_kp = keypoints.Column("kp");
  const int c_x = keypoints.Column("x_laser"), c_y = keypoints.Column("y_laser");
  const int c_theta = keypoints.Column("theta_laser"), c_level = keypoints.Column("scale_level");
  const int c_beam = keypoints.Column("beam");
  const int d_first = descriptors.Column("h_p00_r0");
  std::map<int, std::vector<ReferenceKeypoint>> result;
  for (std::size_t r = 0; r < keypoints.rows.size(); ++r) {
    const auto& row = keypoints.rows[r];
    const auto& drow = descriptors.rows.at(r);
    EXPECT_EQ(drow[descriptors.Column("scan")], row[c_scan]);
    EXPECT_EQ(drow[descriptors.Column("kp")], row[c_kp]);
    ReferenceKeypoint kp;
    kp.position_laser_m = {row[c_x], row[c_y]};
    kp.theta_laser_rad = row[c_theta];
    kp.scale_level = static_cast<int>(row[c_level]);
    kp.beam = static_cast<int>(row[c_beam]);
    for (int b = 0; b < kBetaGridBins; ++b)
      kp.descriptor[b] = static_cast<float>(drow[d_first + b]);
    result[static_cast<int>(row[c_scan])].push_back(kp);
  }
  return result;
}

const CarmenLog& LoadLog(const std::string& dataset) {
  static std::map<std::string, CarmenLog> cache;
  auto it = cache.find(dataset);
  if (it == cache.end()) {
    it = cache
             .emplace(dataset,
                      ReadCarmenLog(testing::SharedFile("data/" + dataset + "-corrected.log.gz")))
             .first;
  }
  return it->second;
}

// FLIRTLib detects on world-frame points built from the laser pose as printed in the log (six
// decimals). Our reader keeps the robot pose and T_robot_laser; their product differs from the
// printed values by a few ulps, which is enough to flip near-equal edge lengths in the spanning
// trees of a handful of scans. Snapping back to the printed grid gives FLIRTLib's exact input.
Pose2 LaserPose(const LogScan& scan) {
  const Pose2 pose = *scan.corrected_pose * scan.T_robot_laser;
  const auto snap = [](double value) { return std::round(value * 1e6) / 1e6; };
  return {snap(pose.x), snap(pose.y), snap(pose.theta)};
}

struct Figures {
  int reference = 0, ours = 0, matched = 0, extra = 0, same_beam = 0;
  double median_chi2 = 0.0, max_chi2 = 0.0, max_theta_error = 0.0;
};

Figures CompareFirst50(const std::string& dataset) {
  const auto reference = ReadReference(dataset);
  const CarmenLog& log = LoadLog(dataset);
  const FlirtExtractor extractor;
  constexpr double kMatchRadius = 0.02;
  Figures f;
  std::vector<double> chi2;
  for (int scan_index = 0; scan_index < 50; ++scan_index) {
    const LogScan& scan = log.scans.at(scan_index);
    const std::vector<Keypoint> ours = extractor.Extract(scan, LaserPose(scan));
    const auto it = reference.find(scan_index);
    const std::vector<ReferenceKeypoint> empty;
    const auto& theirs = it == reference.end() ? empty : it->second;
    f.reference += static_cast<int>(theirs.size());
    f.ours += static_cast<int>(ours.size());
    std::vector<bool> used(ours.size(), false);
    for (const ReferenceKeypoint& ref : theirs) {
      int best = -1;
      double best_distance = kMatchRadius;
      for (std::size_t k = 0; k < ours.size(); ++k) {
        if (used[k] || ours[k].scale_level != ref.scale_level) continue;
        const double distance = (ours[k].position_m - ref.position_laser_m).norm();
        if (distance <= best_distance) {
          best_distance = distance;
          best = static_cast<int>(k);
        }
      }
      if (best < 0) continue;
      used[best] = true;
      ++f.matched;
      f.same_beam += ours[best].beam_index == ref.beam;
      const double c = SymmetricChi2(ours[best].descriptor, ref.descriptor);
      chi2.push_back(c);
      f.max_chi2 = std::max(f.max_chi2, c);
      f.max_theta_error =
          std::max(f.max_theta_error,
                   std::fabs(WrapAngle(ours[best].orientation_rad - ref.theta_laser_rad)));
    }
    for (const bool u : used) f.extra += !u;
  }
  if (!chi2.empty()) {
    std::nth_element(chi2.begin(), chi2.begin() + chi2.size() / 2, chi2.end());
    f.median_chi2 = chi2[chi2.size() / 2];
  }
  return f;
}

void CheckFirst50(const std::string& dataset) {
  const Figures f = CompareFirst50(dataset);
  const double match_fraction = static_cast<double>(f.matched) / f.reference;
  const double extra_fraction = static_cast<double>(f.extra) / f.reference;
  std::cout << std::setprecision(6) << "[flirt " << dataset << " first 50] reference "
            << f.reference << ", ours " << f.ours << ", matched " << f.matched << " ("
            << 100.0 * match_fraction << " %), same beam " << f.same_beam << ", extra " << f.extra
            << " (" << 100.0 * extra_fraction << " %), median chi2 " << f.median_chi2
            << ", max chi2 " << f.max_chi2 << ", max |dtheta| " << f.max_theta_error << " rad\n";
  ::testing::Test::RecordProperty("reference_keypoints", f.reference);
  ::testing::Test::RecordProperty("our_keypoints", f.ours);
  ::testing::Test::RecordProperty("matched_keypoints", f.matched);
  ::testing::Test::RecordProperty("extra_keypoints", f.extra);
  ::testing::Test::RecordProperty("median_chi2", std::to_string(f.median_chi2));
  ::testing::Test::RecordProperty("max_chi2", std::to_string(f.max_chi2));
  ASSERT_GT(f.reference, 0);
  // Acceptance criteria of the features issue.
  EXPECT_GE(match_fraction, 0.90);
  EXPECT_LE(extra_fraction, 0.10);
  EXPECT_LE(f.median_chi2, 0.05);
  // What this implementation actually achieves (regression guard).
  EXPECT_GE(match_fraction, 0.995);
  EXPECT_LE(extra_fraction, 0.005);
  EXPECT_LE(f.median_chi2, 1e-6);
}

TEST(FlirtReference, Fr079First50MatchFlirtLib) { CheckFirst50("fr079"); }
TEST(FlirtReference, IntelFirst50MatchFlirtLib) { CheckFirst50("intel"); }

void CheckCounts(const std::string& dataset) {
  const Table counts =
      ReadTable(testing::SharedFile("reference/flirtlib/" + dataset + "_counts.tsv"));
  const CarmenLog& log = LoadLog(dataset);
  ASSERT_EQ(counts.rows.size(), log.scans.size());
  const int c_n = counts.Column("n_keypoints");
  const FlirtExtractor extractor;
  double theirs = 0.0, ours = 0.0;
  int equal_scans = 0;
  for (std::size_t i = 0; i < log.scans.size(); ++i) {
    const LogScan& scan = log.scans[i];
    const int n = static_cast<int>(extractor.Detect(scan, LaserPose(scan)).size());
    theirs += counts.rows[i][c_n];
    ours += n;
    equal_scans += n == static_cast<int>(counts.rows[i][c_n]);
  }
  const double scans = static_cast<double>(log.scans.size());
  const double mean_theirs = theirs / scans, mean_ours = ours / scans;
  std::cout << std::setprecision(6) << "[flirt " << dataset << " whole log] scans " << scans
            << ", mean keypoints FLIRTLib " << mean_theirs << ", ours " << mean_ours << " (ratio "
            << mean_ours / mean_theirs << "), scans with equal count " << equal_scans << "\n";
  ::testing::Test::RecordProperty("mean_keypoints_flirtlib", std::to_string(mean_theirs));
  ::testing::Test::RecordProperty("mean_keypoints_ours", std::to_string(mean_ours));
  ::testing::Test::RecordProperty("scans_with_equal_count", equal_scans);
  EXPECT_NEAR(mean_ours / mean_theirs, 1.0, 0.05);  // acceptance criterion
  EXPECT_NEAR(mean_ours / mean_theirs, 1.0, 0.001);
  EXPECT_GE(equal_scans, static_cast<int>(0.99 * scans));
}

TEST(FlirtReference, Fr079WholeLogCountsMatchFlirtLib) { CheckCounts("fr079"); }
TEST(FlirtReference, IntelWholeLogCountsMatchFlirtLib) { CheckCounts("intel"); }

}  // namespace
}  // namespace keyplace
