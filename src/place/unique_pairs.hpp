#pragma once
// Algorithm 3's FindUniqueMatch over the pairs below the threshold (internal to src/place).

#include <cstddef>
#include <vector>

#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

/// The unique pairs among `below` (every pair below the threshold with its distance, ordered by
/// current index, then reference index): each keypoint is used at most once, as `mode` says.
std::vector<DescriptorPair> UniquePairs(std::vector<DescriptorPair> below, std::size_t n_current,
                                        std::size_t n_reference,
                                        PlaceRecognitionConfig::PairMatching mode);

}  // namespace keyplace
