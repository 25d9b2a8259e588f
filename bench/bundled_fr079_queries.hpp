#pragma once
// The bundled FR079 map (data/, default mapping) and the queries of `keyplace localize` on it
// (Algorithm 4, 500 equally spaced starts, every 5th kept), built once per benchmark process.

#include <cstddef>
#include <string>
#include <vector>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace_bench {

struct BundledFr079 {
  std::vector<keyplace::Place> places;
  std::vector<keyplace::LocalizationQuery> queries;
};

inline const BundledFr079& LoadBundledFr079() {
  static const BundledFr079 bundled = [] {
    const keyplace::LogInputs inputs = keyplace::PrepareLogInputs(std::string(KEYPLACE_SOURCE_DIR) +
                                                                  "/data/fr079-corrected.log.gz");
    const keyplace::GlobalMap map = keyplace::BuildGlobalMap(
        {inputs.log.scans, inputs.poses, inputs.keypoints}, keyplace::MappingConfig{});
    const keyplace::GroundTruth truth = keyplace::TruthFromOwnPoses(inputs.log);
    const std::vector<keyplace::LocalizationQuery> all =
        keyplace::BuildSubmapQueries(inputs, truth, map.config, keyplace::QueryStarts(truth, 500),
                                     keyplace::PlaceRecognitionConfig{}.query_keypoints);
    BundledFr079 b;
    b.places = keyplace::PlacesFromMap(map);
    for (std::size_t i = 0; i < all.size(); i += 5) b.queries.push_back(all[i]);
    return b;
  }();
  return bundled;
}

}  // namespace keyplace_bench
