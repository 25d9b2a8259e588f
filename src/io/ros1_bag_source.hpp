#pragma once
// Internal: the messages of a ROS 1 bag as bytes, from Debian's rosbag library (the bag's index,
// time order) or, for a bag whose index is missing (a recorder cut off), by walking its complete
// chunks in file order.

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

/// Thrown by VisitIndexedBag when rosbag cannot open the bag (no or damaged index, cut off).
struct BagIndexError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws BagIndexError unless every record of the bag lies within the file and every compressed
/// chunk claims a plausible uncompressed size (chunk_limits.hpp): rosbag trusts these lengths and
/// allocates what they say (a hostile 4-byte field made it ask for 1.1 GB).
void CheckBagRecords(const std::string& path);

/// The messages on `topics` in time order, through rosbag (after CheckBagRecords). Throws
/// BagIndexError when the bag cannot be opened, std::invalid_argument naming the bag and topic when
/// a chunk cannot be read (e.g. an unknown compression).
BagSummary VisitIndexedBag(const std::string& path, const std::set<std::string>& topics,
                           const RawMessageVisitor& visitor);

/// The messages on `topics` of every complete chunk, in file order, without the index; what is
/// cut off is named in BagSummary::warnings. Throws std::invalid_argument naming the bag when
/// not even the first chunk is complete or a chunk cannot be decompressed.
BagSummary VisitBagChunks(const std::string& path, const std::set<std::string>& topics,
                          const RawMessageVisitor& visitor);

}  // namespace keyplace
