#pragma once
// Keypoints extracted ahead of their consumer: a thread of its own extracts the keypoints of a
// log's scans in a given order, a batch at a time (the scans of a batch in parallel), as far
// ahead as it gets, while the consumer (SLAM, one scan at a time) takes them as they become
// ready. On two cores SLAM then runs beside the extraction instead of after it.

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "keyplace/features/flirt.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace {

class KeypointStream {
 public:
  /// Starts extracting the keypoints of log.scans[order[0]], log.scans[order[1]], ... (laser
  /// frame, as ExtractKeypoints). `log` and `order` must outlive the stream.
  KeypointStream(const CarmenLog& log, const std::vector<std::size_t>& order,
                 const FlirtConfig& features);
  /// Stops the extraction after its current batch and waits for it.
  ~KeypointStream();
  KeypointStream(const KeypointStream&) = delete;
  KeypointStream& operator=(const KeypointStream&) = delete;

  /// The keypoints of log.scans[order[k]], waiting until they are extracted; rethrows what the
  /// extraction threw for a scan of k's batch (32 scans) or an earlier one. Throws
  /// std::out_of_range for k >= order.size().
  const std::vector<Keypoint>& Wait(std::size_t k);
  /// Wall time from the start to the last scan extracted (0 before that).
  double seconds() const;

 private:
  void Run();

  const CarmenLog& log_;
  const std::vector<std::size_t>& order_;
  const FlirtExtractor extractor_;
  std::vector<std::vector<Keypoint>> keypoints_;  // by scan index

  mutable std::mutex mutex_;
  std::condition_variable ready_changed_;
  std::size_t ready_ = 0;  // order_[0 .. ready_) extracted
  std::exception_ptr error_;
  bool stop_ = false;
  double seconds_ = 0.0;
  std::thread thread_;  // last: started once everything above is in place
};

}  // namespace keyplace
