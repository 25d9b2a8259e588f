#include "mapping/keypoint_stream.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace {
namespace {

// Scans per batch: the consumer waits at most one batch's extraction for a scan, and a batch
// still spreads over the cores (about 20 ms of FLIRT for 32 scans of 180 beams on one core).
constexpr std::size_t kBatchScans = 32;

}  // namespace

KeypointStream::KeypointStream(const CarmenLog& log, const std::vector<std::size_t>& order,
                               const FlirtConfig& features)
    : log_(log), order_(order), extractor_(features), keypoints_(log.scans.size()) {
  thread_ = std::thread([this] { Run(); });
}

KeypointStream::~KeypointStream() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  thread_.join();
}

void KeypointStream::Run() {
  const auto start = std::chrono::steady_clock::now();
  try {
    for (std::size_t begin = 0; begin < order_.size(); begin += kBatchScans) {
      const std::size_t end = std::min(begin + kBatchScans, order_.size());
      tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 4),
                        [this](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t k = range.begin(); k != range.end(); ++k) {
                            const LogScan& scan = log_.scans.at(order_[k]);
                            keypoints_[order_[k]] = extractor_.Extract(scan, LogLaserPose(scan));
                          }
                        });
      const std::lock_guard<std::mutex> lock(mutex_);
      ready_ = end;
      if (end == order_.size()) {
        seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
      ready_changed_.notify_all();
      if (stop_) return;
    }
  } catch (...) {
    const std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
    ready_changed_.notify_all();
  }
}

const std::vector<Keypoint>& KeypointStream::Wait(std::size_t k) {
  if (k >= order_.size()) {
    throw std::out_of_range("KeypointStream::Wait: scan " + std::to_string(k) + " of " +
                            std::to_string(order_.size()));
  }
  std::unique_lock<std::mutex> lock(mutex_);
  ready_changed_.wait(lock, [&] { return ready_ > k || error_; });
  if (ready_ <= k) std::rethrow_exception(error_);
  return keypoints_[order_.at(k)];
}

double KeypointStream::seconds() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return seconds_;
}

}  // namespace keyplace
