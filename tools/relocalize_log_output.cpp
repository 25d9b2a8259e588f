#include "relocalize_log_output.hpp"

#include <cmath>

#include <fmt/core.h>
#include <fmt/ostream.h>

#include "io/atomic_file.hpp"

namespace keyplace::cli {
namespace {

double Degrees(double radians) { return radians * 180.0 / M_PI; }

}  // namespace

void PrintLogRelocalization(const LogRelocalization& run, const LogInputs& inputs,
                            const std::string& map_path, const GlobalMap& map,
                            const std::string& log_path) {
  fmt::print("map          {} ({} submaps, built from {})\n", map_path, map.submaps.size(),
             map.source_log);
  fmt::print("log          {} (scans {}:{}, {} poses as odometry)\n", log_path, inputs.first_scan,
             inputs.first_scan + inputs.log.scans.size(), ToString(inputs.pose_source));
  fmt::print(
      "protocol     no truth: the log relocalized once from its first scan, as a robot "
      "would be (no benchmark)\n");
  const double path_m = run.scans.empty() ? 0.0 : run.scans.back().odometry_m;
  if (run.first_fix) {
    const RelocalizedScan& fix = run.scans[*run.first_fix];
    fmt::print(
        "first fix    scan {} (stamp {:.3f} s) after {:.1f} m of {:.1f} m: x {:.3f} m, y {:.3f} "
        "m, theta {:.1f} deg, confidence {:.3f}\n",
        fix.scan, fix.stamp_s, fix.odometry_m, path_m, fix.T_world_robot.x, fix.T_world_robot.y,
        Degrees(fix.T_world_robot.theta), fix.confidence);
  } else {
    fmt::print("first fix    none in {:.1f} m of odometry ({} answers)\n", path_m, run.answers);
  }
  std::size_t fixed_scans = 0;
  for (const RelocalizedScan& scan : run.scans) fixed_scans += scan.status == FixStatus::kFixed;
  fmt::print("track        {} fixes, {} losses, {} answers; fixed at {} of {} scans\n", run.fixes,
             run.losses, run.answers, fixed_scans, run.scans.size());
  fmt::print("update       {:.2f} ms mean, {:.1f} ms max per scan (keypoints given)\n",
             1e3 * run.update_seconds_mean, 1e3 * run.update_seconds_max);
  if (run.map_searches > 0) {
    fmt::print(
        "search       {} of the whole map, mean {:.1f} ms (a robot's node runs them in the "
        "background)\n",
        run.map_searches, 1e3 * run.map_search_seconds / static_cast<double>(run.map_searches));
  }
}

void WriteScanStatusTsv(const std::string& path, const LogRelocalization& run) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "scan\tstamp_s\todometry_m\tstatus\tnew_fix\tlost\tanswered\tx_m\ty_m\ttheta_rad\t"
           "confidence\tupdate_seconds\n";
    for (const RelocalizedScan& s : run.scans) {
      const bool fixed = s.status == FixStatus::kFixed;
      fmt::print(out, "{}\t{:.6f}\t{:.3f}\t{}\t{:d}\t{:d}\t{:d}\t", s.scan, s.stamp_s, s.odometry_m,
                 ToString(s.status), s.new_fix, s.lost, s.answered);
      if (fixed) {
        fmt::print(out, "{:.4f}\t{:.4f}\t{:.5f}\t{:.4f}", s.T_world_robot.x, s.T_world_robot.y,
                   s.T_world_robot.theta, s.confidence);
      } else {
        out << "\t\t\t";  // no pose without a fix
      }
      fmt::print(out, "\t{:.6f}\n", s.update_seconds);
    }
  });
}

nlohmann::json LogRelocalizationJson(const LogRelocalization& run, const LogInputs& inputs,
                                     const std::string& map_path, const std::string& log_path) {
  nlohmann::json json;
  json["map"] = map_path;
  json["log"] = log_path;
  json["truth"] = false;
  json["pose_source"] = ToString(inputs.pose_source);
  json["first_scan"] = inputs.first_scan;
  json["scans"] = run.scans.size();
  json["odometry_m"] = run.scans.empty() ? 0.0 : run.scans.back().odometry_m;
  json["fixes"] = run.fixes;
  json["losses"] = run.losses;
  json["answers"] = run.answers;
  json["update_seconds_mean"] = run.update_seconds_mean;
  json["update_seconds_max"] = run.update_seconds_max;
  nlohmann::json first = nullptr;
  if (run.first_fix) {
    const RelocalizedScan& fix = run.scans[*run.first_fix];
    first = {{"scan", fix.scan},
             {"stamp_s", fix.stamp_s},
             {"odometry_m", fix.odometry_m},
             {"x_m", fix.T_world_robot.x},
             {"y_m", fix.T_world_robot.y},
             {"theta_rad", fix.T_world_robot.theta},
             {"confidence", fix.confidence}};
  }
  json["first_fix"] = first;
  return json;
}

}  // namespace keyplace::cli
