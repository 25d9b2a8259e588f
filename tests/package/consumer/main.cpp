// Reads a log through the installed library, builds a small map of its first scans and streams
// the next scans through the GlobalLocalizer (the robot program's API); prints the scan count.
#include <iostream>

#include "keyplace/config/config.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  keyplace::LogInputOptions options;
  options.end_scan = 300;
  const keyplace::LogInputs inputs = keyplace::PrepareLogInputs(argv[1], options);
  const keyplace::GlobalMap map = keyplace::BuildGlobalMap(
      {inputs.log.scans, inputs.poses, inputs.keypoints}, keyplace::MappingConfig{});
  keyplace::GlobalLocalizer localizer(map);
  int answers = 0;
  for (std::size_t k = 0; k < inputs.log.scans.size(); ++k) {
    if (localizer.AddScan(inputs.log.scans[k], inputs.poses[k])) ++answers;
  }
  // The configuration goes through yaml-cpp, a private dependency of the static library.
  if (keyplace::ConfigToYaml(keyplace::Config{}).empty() || answers == 0) return 1;
  std::cout << inputs.file_scans << "\n";
  return 0;
}
