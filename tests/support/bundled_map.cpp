#include "support/bundled_map.hpp"

#include "keyplace/mapping/global_mapper.hpp"
#include "support/test_data.hpp"

namespace keyplace::testing {

const BundledMap& BundledFr079() {
  static const BundledMap bundled = [] {
    BundledMap b;
    b.inputs = PrepareLogInputs(SourceDir() + "/data/fr079-corrected.log.gz");
    b.map =
        BuildGlobalMap({b.inputs.log.scans, b.inputs.poses, b.inputs.keypoints}, MappingConfig{});
    b.truth = TruthFromOwnPoses(b.inputs.log);
    return b;
  }();
  return bundled;
}

}  // namespace keyplace::testing
