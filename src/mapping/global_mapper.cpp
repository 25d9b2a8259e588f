#include "keyplace/mapping/global_mapper.hpp"

#include <chrono>
#include <stdexcept>

namespace keyplace {
namespace {

void CheckSequence(const ScanSequence& sequence) {
  if (sequence.poses.size() != sequence.scans.size() ||
      sequence.keypoints.size() != sequence.scans.size()) {
    throw std::invalid_argument("ScanSequence: poses (" + std::to_string(sequence.poses.size()) +
                                ") and keypoints (" + std::to_string(sequence.keypoints.size()) +
                                ") must have one entry per scan (" +
                                std::to_string(sequence.scans.size()) + ")");
  }
}

}  // namespace

std::optional<Submap> BuildSubmap(const ScanSequence& sequence, std::size_t first_scan,
                                  LocalMapper& mapper) {
  CheckSequence(sequence);
  mapper.Reset();
  for (std::size_t index = first_scan; index < sequence.size(); ++index) {
    if (mapper.AddScan(static_cast<int>(index), sequence.scans[index], sequence.poses[index],
                       sequence.keypoints[index])) {
      return mapper.Snapshot();
    }
  }
  return std::nullopt;
}

GlobalMap BuildGlobalMap(const ScanSequence& sequence, const MappingConfig& config,
                         GlobalMappingTimings* timings,
                         const std::function<void(std::size_t)>& progress) {
  CheckSequence(sequence);
  Validate(config);
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  GlobalMap map;
  map.config = config;
  map.source_scans = sequence.size();
  for (const auto& keypoints : sequence.keypoints) map.source_keypoints += keypoints.size();

  LocalMapper mapper(config);
  std::size_t next_scan = 0;
  while (next_scan < sequence.size()) {
    const auto submap_start = Clock::now();
    std::optional<Submap> submap = BuildSubmap(sequence, next_scan, mapper);
    if (!submap) break;
    submap->id = static_cast<int>(map.submaps.size());
    next_scan = static_cast<std::size_t>(submap->last_scan()) + 1;
    map.submaps.push_back(std::move(*submap));
    if (timings != nullptr) {
      timings->submap_seconds.push_back(
          std::chrono::duration<double>(Clock::now() - submap_start).count());
    }
    if (progress) progress(next_scan);
  }
  if (timings != nullptr) {
    timings->seconds_total = std::chrono::duration<double>(Clock::now() - start).count();
  }
  return map;
}

}  // namespace keyplace
