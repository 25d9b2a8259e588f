#pragma once
// Internal: the messages of a ROS 1 bag as bytes, read through the bag's index (time order) or,
// for a bag whose index is missing (a recorder cut off), by walking its complete chunks in file
// order.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "io/bag_log.hpp"

namespace keyplace {

/// One serialized message and where it came from.
struct RawBagMessage {
  const std::string& topic;
  const std::string& datatype;
  const std::string& md5sum;
  std::uint32_t receive_sec = 0;  // the recorder's time
  std::uint32_t receive_nsec = 0;
  const std::uint8_t* data = nullptr;
  std::uint32_t size = 0;
};

using RawMessageVisitor = std::function<void(const RawBagMessage&)>;

/// Thrown by VisitIndexedBag when the bag has no usable index (missing or damaged, cut off).
struct BagIndexError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The messages on `topics` in the bag's time order (that of rosbag's View), read through the
/// bag's index by keyplace (ros1_bag_index.cpp), each chunk decompressed once. Throws
/// BagIndexError when the bag has no usable index: a record runs past the end of the file or a
/// compressed chunk claims an implausible size (chunk_limits.hpp), the index is not where the bag
/// header says (missing: a recording cut off), or its records are not as long as their counts say.
/// Throws std::invalid_argument naming the bag when an index entry points at anything but a
/// message record of its own connection in its chunk, a chunk cannot be decompressed (e.g. an
/// unknown compression) or the bag is encrypted.
BagSummary VisitIndexedBag(const std::string& path, const std::set<std::string>& topics,
                           const RawMessageVisitor& visitor);

/// The messages on `topics` of every complete chunk, in file order, without the index; what is
/// cut off is named in BagSummary::warnings. Throws std::invalid_argument naming the bag when
/// not even the first chunk is complete or a chunk cannot be decompressed.
BagSummary VisitBagChunks(const std::string& path, const std::set<std::string>& topics,
                          const RawMessageVisitor& visitor);

}  // namespace keyplace
