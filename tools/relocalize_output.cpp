#include "relocalize_output.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/core.h>
#include <fmt/ostream.h>

#include "io/atomic_file.hpp"
#include "relocalization_figure.hpp"
#include "result_json.hpp"
#include "result_tsv.hpp"

namespace keyplace::cli {

void PrintRelocalizeReport(const RelocalizeReport& r, const GlobalMap& map) {
  const RelocalizationSummary& s = r.summary;
  const RelocalizationOptions& o = r.options;
  fmt::print("map          {} ({} submaps, built from {})\n", r.map_path, map.submaps.size(),
             map.source_log);
  fmt::print("log          {} (scans {}:{}, {} poses as odometry)\n", r.log_path, r.first_scan,
             r.end_scan, ToString(r.pose_source));
  int last_map_scan = -1;
  for (const Submap& submap : map.submaps) {
    for (const int scan : submap.scan_indices) last_map_scan = std::max(last_map_scan, scan);
  }
  const bool time_split = static_cast<int>(r.first_scan) > last_map_scan;
  fmt::print("protocol     {}\n",
             !r.query_log_is_map_log ? "another recording than the map's: nothing excluded"
             : time_split ? "time split: the map's own log, queries after the map's last scan"
             : o.exclude_shared_scans
                 ? "the map's own log: submaps sharing a scan with the query are excluded"
                 : "the map's own log, nothing excluded (self-matches allowed)");
  fmt::print("starts       {} ({} pass a map scan within {} m / {} deg before {} m)\n", s.starts,
             s.starts_with_revisit, o.revisit_m, o.revisit_deg, o.give_up_m);
  fmt::print("fixed        {:.3f} of starts with a revisit ({}/{}); {} starts in all\n",
             s.fixed_fraction, s.fixed_with_revisit, s.starts_with_revisit, s.fixed);
  fmt::print(
      "with room    {:.3f} of the starts with at least {} m of path after the revisit ({}/{})\n",
      s.fixed_fraction_with_room, o.revisit_room_m, s.fixed_with_room, s.starts_with_room);
  fmt::print("to first fix median {:.2f} m, 90th percentile {:.2f} m, median {:.0f} scans\n",
             s.distance_to_fix_median_m, s.distance_to_fix_p90_m, s.scans_to_fix_median);
  fmt::print("after known  median {:.2f} m, 90th percentile {:.2f} m from the first mapped place\n",
             s.distance_after_revisit_median_m, s.distance_after_revisit_p90_m);
  fmt::print(
      "fixes        {} checked over {} m after each first fix, {} wrong (rate {:.4f}); "
      "{} wrong first fixes\n",
      s.fixes, o.follow_m, s.wrong_fixes, s.wrong_fix_rate, s.wrong_first_fixes);
  fmt::print("wrong fixes  {} (highest confidence {:.3f}, confident = {})\n",
             s.wrong_fix_confident ? "one was reported as confident" : "none was confident",
             s.wrong_fix_confidence_max, o.confident);
  fmt::print("lost         {} signals: {} on a correct track, {} on a wrong one\n", s.lost_signals,
             s.lost_on_correct_track, s.lost_on_wrong_track);
  fmt::print("update       mean {:.2f} ms, max {:.1f} ms per AddScan with keypoints given; {}\n",
             1e3 * s.update_seconds_mean, 1e3 * s.update_seconds_max,
             r.seconds_keypoints_per_scan
                 ? fmt::format("FLIRT {:.2f} ms per scan", 1e3 * *r.seconds_keypoints_per_scan)
                 : std::string("keypoints read from the cache"));
  if (s.map_searches > 0) {
    fmt::print(
        "search       {} of the whole map, mean {:.1f} ms; updates without them mean {:.2f} ms "
        "(a robot's node runs them in the background)\n",
        s.map_searches, 1e3 * s.map_search_seconds_mean,
        1e3 * s.update_seconds_mean_without_search);
  }
  fmt::print("time         {:.1f} s\n", r.seconds_total);
}

void WriteStartsTsv(const std::string& path, const std::vector<StartRecord>& records) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << ResultTsvHeader(StartRecordFields()) << '\n';
    for (const StartRecord& r : records) out << ResultTsvRow(r, StartRecordFields()) << '\n';
  });
}

// A fix's figures (FixEventFields), then its estimate, the truth and the covariance at `scan`.
void WriteFixesTsv(const std::string& path, const std::vector<StartRecord>& records) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "start_scan\t" << ResultTsvHeader(FixEventFields())
        << "\test_x\test_y\test_theta\ttrue_x\ttrue_y\ttrue_theta\tcov_xx\tcov_xy\tcov_yy\t"
           "cov_xtheta\tcov_ytheta\tcov_thetatheta\n";
    for (const StartRecord& r : records) {
      for (const FixEvent& f : r.fixes) {
        const Eigen::Matrix3d& c = f.initial_pose.covariance;
        fmt::print(out, "{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\n", r.start_scan,
                   ResultTsvRow(f, FixEventFields()), f.T_world_robot.x, f.T_world_robot.y,
                   f.T_world_robot.theta, f.truth.x, f.truth.y, f.truth.theta, c(0, 0), c(0, 1),
                   c(1, 1), c(0, 2), c(1, 2), c(2, 2));
      }
    }
  });
}

nlohmann::json RelocalizeJson(const RelocalizeReport& r) {
  const RelocalizationSummary& s = r.summary;
  const RelocalizationOptions& o = r.options;
  nlohmann::json json;
  json["map"] = r.map_path;
  json["log"] = r.log_path;
  json["scans"] = {r.first_scan, r.end_scan};
  json["pose_source"] = ToString(r.pose_source);
  json["query_log_is_map_log"] = r.query_log_is_map_log;
  json["exclude_shared_scans"] = o.exclude_shared_scans;
  json["give_up_m"] = o.give_up_m;
  json["follow_m"] = o.follow_m;
  json["revisit_room_m"] = o.revisit_room_m;
  AddResultFields(s, RelocalizationSummaryFields(), json);
  json["keypoint_seconds_per_scan"] = r.seconds_keypoints_per_scan
                                          ? nlohmann::json(*r.seconds_keypoints_per_scan)
                                          : nlohmann::json(nullptr);
  json["seconds_total"] = r.seconds_total;
  return json;
}

void DrawRelocalization(const std::string& path, const RelocalizeReport& report,
                        const GlobalMap& map, const LogInputs& inputs, const GroundTruth& truth) {
  std::vector<Eigen::Vector2d> map_positions;
  for (const Submap& submap : map.submaps) {
    for (const Pose2& pose : submap.poses) map_positions.push_back(pose.translation());
  }
  std::vector<StartDrawing> starts;
  for (const StartRecord& r : report.records) {
    StartDrawing drawing;
    const int last = r.fixed ? r.start_scan + r.scans_to_fix : r.end_scan;
    for (int k = r.start_scan; k < last && k < static_cast<int>(inputs.log.scans.size()); ++k) {
      if (truth.Has(static_cast<std::size_t>(k))) {
        drawing.path_to_fix.push_back(truth.Pose(static_cast<std::size_t>(k)).translation());
      }
    }
    for (const FixEvent& fix : r.fixes) {
      if (!fix.correct) {
        drawing.wrong_fixes.push_back(fix.T_world_robot.translation());
      } else if (fix.first) {
        drawing.correct_fixes.push_back(fix.T_world_robot.translation());
      }
    }
    starts.push_back(std::move(drawing));
  }
  const RelocalizationSummary& s = report.summary;
  DrawRelocalizationFigure(
      path,
      fmt::format("{}: {} starts, {:.0f} % fixed, median {:.1f} m to fix, {} wrong of {} fixes",
                  std::filesystem::path(report.log_path).filename().string(), s.starts,
                  100.0 * s.fixed_fraction, s.distance_to_fix_median_m, s.wrong_fixes, s.fixes),
      map_positions, starts);
}

}  // namespace keyplace::cli
