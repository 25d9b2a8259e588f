#include "keyplace/mapping/scan_sources.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "common/config_fields.hpp"
#include "common/seconds_since.hpp"
#include "features/features_fields.hpp"
#include "io/atomic_file.hpp"
#include "io/io_fields.hpp"
#include "keyplace_generated/preparation_code_hash.hpp"
#include "mapping/preparation_cache.hpp"
#include "registration/registration_fields.hpp"

namespace keyplace {

PoseSource ParsePoseSource(const std::string& text) {
  if (text == "corrected") return PoseSource::kCorrected;
  if (text == "odometry") return PoseSource::kOdometry;
  if (text == "icp") return PoseSource::kIcp;
  throw std::invalid_argument("pose source '" + text + "' is not one of: corrected, odometry, icp");
}

std::string ToString(PoseSource source) {
  switch (source) {
    case PoseSource::kCorrected:
      return "corrected";
    case PoseSource::kOdometry:
      return "odometry";
    case PoseSource::kIcp:
      return "icp";
  }
  return "?";
}

Pose2 LogLaserPose(const LogScan& scan) { return scan.logged_laser_pose; }

std::vector<Pose2> ScanPoses(const CarmenLog& log, PoseSource source,
                             const ScanOdometryConfig& icp_config,
                             const ProgressCallback& progress) {
  std::vector<Pose2> poses;
  poses.reserve(log.scans.size());
  if (source == PoseSource::kIcp) {
    ScanOdometry odometry(icp_config);
    for (std::size_t i = 0; i < log.scans.size(); ++i) {
      poses.push_back(odometry.Add(log.scans[i], log.scans[i].odometry_pose).T_world_robot);
      if (progress) progress(i + 1, log.scans.size());
    }
    return poses;
  }
  for (std::size_t i = 0; i < log.scans.size(); ++i) {
    const LogScan& scan = log.scans[i];
    const auto& pose = source == PoseSource::kCorrected ? scan.corrected_pose : scan.odometry_pose;
    if (!pose) {
      // What to ask for instead: the CLI's --poses, PoseSource in the library.
      const std::string hint =
          log.corrected ? " (--poses corrected)"
                        : " (a raw log: --poses icp matches its scans from the odometry, --poses "
                          "odometry takes the odometry as it is)";
      throw std::invalid_argument(log.path + ": scan " + std::to_string(i) + " (line " +
                                  std::to_string(scan.line) + ") has no " + ToString(source) +
                                  " pose; this log holds " +
                                  (log.corrected ? "corrected" : "odometry") + " poses" + hint);
    }
    poses.push_back(*pose);
  }
  if (progress) progress(log.scans.size(), log.scans.size());
  return poses;
}

std::vector<std::vector<Keypoint>> ExtractKeypoints(const CarmenLog& log,
                                                    const FlirtExtractor& extractor,
                                                    const ProgressCallback& progress) {
  std::vector<std::vector<Keypoint>> keypoints(log.scans.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, log.scans.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        keypoints[i] = extractor.Extract(log.scans[i], LogLaserPose(log.scans[i]));
                      }
                    });
  if (progress) progress(log.scans.size(), log.scans.size());
  return keypoints;
}

namespace {

template <typename Config>
void AppendSettings(const std::string& section, const ConfigFields<Config>& fields,
                    const Config& config, std::string& key) {
  for (const auto& [name, value] : fields.ToKeyValues(config)) {
    // The value's length first: a text value holding a newline cannot pass for another key.
    key.append(section).append(".").append(name).append("=");
    key.append(std::to_string(value.size())).append(":").append(value).append("\n");
  }
}

// Everything a cache entry of `kind` ("poses-icp" or "keypoints") depends on, spelled out: the
// code that computes it (a hash of its sources made by the build), the log's content, the scans
// kept and every setting.
std::string CacheKey(const std::string& kind, const LogInputs& inputs,
                     const LogInputOptions& options) {
  const CarmenReadOptions& reading = options.reading;
  std::string key = "keyplace preparation 1\ncode " KEYPLACE_PREPARATION_CODE_HASH "\n" + kind +
                    "\nlog " + inputs.source_hash + "\nscans " + std::to_string(inputs.first_scan) +
                    ":" + std::to_string(inputs.first_scan + inputs.log.scans.size()) + " of " +
                    std::to_string(inputs.file_scans) + "\nreading flaser_max_range_m=" +
                    FormatConfigDouble(reading.flaser_max_range_m) +
                    " max_coordinate_m=" + FormatConfigDouble(reading.max_coordinate_m) +
                    " pose_kind=" + std::to_string(static_cast<int>(reading.pose_kind)) +
                    " skip_bad_lines=" + (reading.skip_bad_lines ? "1" : "0") +
                    " keep_beams=" + (reading.keep_beams ? "1" : "0") + "\n";
  AppendSettings("input", BagInputConfigFields(), reading.bag, key);
  if (kind == "keypoints") AppendSettings("features", FlirtConfigFields(), options.features, key);
  if (kind == "poses-icp") {
    AppendSettings("odometry", ScanOdometryConfigFields(), options.odometry, key);
  }
  return key;
}

// The value of a cache entry: read from options.cache_dir when there, else computed and written
// there. Returns whether it was read.
template <typename Value>
bool ReadOrCompute(const std::string& kind, const LogInputOptions& options, LogInputs& inputs,
                   Value& value, const std::function<Value()>& compute,
                   const std::function<std::string(const Value&)>& encode,
                   const std::function<Value(const std::string&, std::size_t)>& decode) {
  if (options.cache_dir.empty()) {
    value = compute();
    return false;
  }
  const std::string key = CacheKey(kind, inputs, options);
  const std::string path = mapping_internal::CacheEntryPath(options.cache_dir, kind, key);
  mapping_internal::CacheRead read = mapping_internal::ReadCacheEntry(path, key);
  if (read.payload) {
    try {
      value = decode(*read.payload, inputs.log.scans.size());
      return true;
    } catch (const std::runtime_error& error) {
      read.problem = error.what();
    }
  }
  if (!read.problem.empty()) {
    inputs.cache_warnings.push_back(path + ": " + read.problem + "; computed again");
  }
  value = compute();
  try {
    mapping_internal::WriteCacheEntry(path, key, encode(value));
  } catch (const std::runtime_error& error) {  // the results stand; only the next run pays
    inputs.cache_warnings.push_back(std::string(error.what()) + "; not cached");
  }
  return false;
}

// Makes the cache directory and checks that entries can be written there, before any work.
void PrepareCacheDir(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    throw std::invalid_argument(dir + ": cannot make the cache directory (" + error.message() +
                                ")");
  }
  CheckOutputPath(dir + "/keypoints-probe.bin", {});
}

}  // namespace

LogInputs PrepareLogInputs(const std::string& path, const LogInputOptions& options,
                           const StageProgress& progress) {
  if (!options.cache_dir.empty()) PrepareCacheDir(options.cache_dir);
  auto start = std::chrono::steady_clock::now();
  LogInputs inputs;
  inputs.log = ReadCarmenLogWithScans(path, options.reading);
  std::vector<LogScan>& scans = inputs.log.scans;
  inputs.file_scans = scans.size();
  const std::size_t end = std::min(options.end_scan, scans.size());
  const std::size_t begin = std::min(options.first_scan, end);
  scans.erase(scans.begin() + static_cast<std::ptrdiff_t>(end), scans.end());
  scans.erase(scans.begin(), scans.begin() + static_cast<std::ptrdiff_t>(begin));
  if (scans.empty()) {
    throw std::invalid_argument(path + ": no scan in the range " + std::to_string(begin) + ":" +
                                std::to_string(end));
  }
  inputs.first_scan = begin;
  inputs.source_log = std::filesystem::path(path).filename().string();
  inputs.source_hash = inputs.log.fingerprint;  // the log is read once: it may be a pipe
  inputs.seconds_read = SecondsSince(start);

  start = std::chrono::steady_clock::now();
  inputs.pose_source =
      options.poses.value_or(inputs.log.corrected ? PoseSource::kCorrected : PoseSource::kIcp);
  if (options.compute_poses) {
    const std::string pose_stage = "poses (" + ToString(inputs.pose_source) + ")";
    const auto compute = [&] {
      return ScanPoses(inputs.log, inputs.pose_source, options.odometry,
                       [&](std::size_t done, std::size_t total) {
                         if (progress) progress(pose_stage, done, total);
                       });
    };
    if (inputs.pose_source == PoseSource::kIcp) {  // the others are read from the log
      inputs.poses_from_cache = ReadOrCompute<std::vector<Pose2>>(
          "poses-icp", options, inputs, inputs.poses, compute, mapping_internal::EncodePoses,
          mapping_internal::DecodePoses);
    } else {
      inputs.poses = compute();
    }
    inputs.start_at_origin = options.start_at_origin;
    if (options.start_at_origin) {
      const Pose2 T_first_world = inputs.poses.front().inverse();
      for (Pose2& pose : inputs.poses) pose = T_first_world * pose;
    }
    inputs.seconds_poses = SecondsSince(start);
  }

  if (options.keypoints) {
    start = std::chrono::steady_clock::now();
    inputs.keypoints_from_cache = ReadOrCompute<std::vector<std::vector<Keypoint>>>(
        "keypoints", options, inputs, inputs.keypoints,
        [&] {
          const FlirtExtractor extractor(options.features);
          return ExtractKeypoints(inputs.log, extractor, [&](std::size_t done, std::size_t total) {
            if (progress) progress("keypoints", done, total);
          });
        },
        mapping_internal::EncodeKeypoints, mapping_internal::DecodeKeypoints);
    inputs.seconds_keypoints = SecondsSince(start);
  }
  return inputs;
}

LogMap MapLog(const LogInputs& inputs, const MappingConfig& config,
              const std::function<void(std::size_t)>& progress) {
  LogMap result;
  result.map = BuildGlobalMap({inputs.log.scans, inputs.poses, inputs.keypoints}, config,
                              &result.timings, progress);
  // The mapper numbers the scans of the cut log; a map names scans of the whole file, so that a
  // map of scans A:B and queries of scans C:D of one log apply the self-match rule to the same
  // numbers (the time-split protocol).
  const int offset = static_cast<int>(inputs.first_scan);
  if (offset != 0) {
    for (Submap& submap : result.map.submaps) {
      for (int& index : submap.scan_indices) index += offset;
      for (StableKeypoint& keypoint : submap.keypoints) keypoint.scan_index += offset;
    }
  }
  result.map.source_log = inputs.source_log;
  result.map.source_hash = inputs.source_hash;
  // A map in its first scan's frame is not in its log's frame: say so wherever it is read, so
  // that the log's own poses are not taken for its truth without a word.
  result.map.pose_source =
      ToString(inputs.pose_source) + (inputs.start_at_origin ? " (first-scan frame)" : "");
  result.stats = ComputeStats(result.map);
  const std::vector<double>& seconds = result.timings.submap_seconds;
  if (!seconds.empty()) {
    double sum = 0.0;
    for (const double s : seconds) sum += s;
    result.seconds_per_submap_mapping = sum / static_cast<double>(seconds.size());
  }
  if (result.stats.submaps > 0) {
    result.seconds_per_submap =
        result.seconds_per_submap_mapping + (inputs.seconds_poses + inputs.seconds_keypoints) /
                                                static_cast<double>(result.stats.submaps);
  }
  return result;
}

OccupancyGrid LogOccupancyGrid(const LogInputs& inputs, const OccupancyGridConfig& config) {
  if (inputs.poses.size() != inputs.log.scans.size()) {
    throw std::invalid_argument(inputs.source_log +
                                ": an occupancy grid needs a pose for every scan");
  }
  std::vector<const LaserScan*> scans;
  scans.reserve(inputs.log.scans.size());
  for (const LogScan& scan : inputs.log.scans) scans.push_back(&scan);
  return BuildOccupancyGrid(scans, inputs.poses, config);
}

}  // namespace keyplace
