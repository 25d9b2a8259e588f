#pragma once
// Progress of work done in parallel (TBB): the items finished so far counted under a mutex and the
// callback called under it, so that it sees 1, 2, ..., total in order and never from two threads
// at once, whichever threads finish the items.

#include <cstddef>
#include <functional>
#include <mutex>
#include <utility>

namespace keyplace {

class ParallelProgress {
 public:
  /// `callback` gets (items done, total); empty = no progress.
  ParallelProgress(std::function<void(std::size_t, std::size_t)> callback, std::size_t total)
      : callback_(std::move(callback)), total_(total) {}

  /// One more item is finished (any thread).
  void ItemDone() {
    if (!callback_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    callback_(++done_, total_);
  }

 private:
  std::function<void(std::size_t, std::size_t)> callback_;
  std::size_t total_ = 0;
  std::size_t done_ = 0;
  std::mutex mutex_;
};

}  // namespace keyplace
