#include "keyplace/config/config.hpp"

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::string ErrorOfYaml(const std::string& yaml) {
  Config config;
  try {
    ApplyConfigYaml(yaml, "my.yaml", config);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(Config, DumpLoadDumpIsIdenticalForEveryPreset) {
  for (const std::string& preset : ConfigPresetNames()) {
    const Config original = PresetConfig(preset);
    const std::string yaml = ConfigToYaml(original);
    Config loaded;  // the defaults: the dump must carry every difference of the preset
    ApplyConfigYaml(yaml, "dump", loaded);
    EXPECT_EQ(ConfigToYaml(loaded), yaml) << preset;
    EXPECT_EQ(ConfigKeyValues(loaded), ConfigKeyValues(original)) << preset;
  }
}

TEST(Config, ChangedValuesSurviveTheRoundTripExactly) {
  Config config;
  config.place.ransac.inlier_distance_m = 0.1 + 0.2;  // needs all 17 digits
  config.place.selection = PlaceRecognitionConfig::Selection::kFirstVerified;
  config.odometry.icp.kernel = RobustKernel::kTukey;
  config.slam.loop_refinement.refine = false;
  config.mapping.max_scans_per_submap = 123;
  Config loaded;
  ApplyConfigYaml(ConfigToYaml(config), "dump", loaded);
  EXPECT_EQ(loaded.place.ransac.inlier_distance_m, 0.1 + 0.2);
  EXPECT_EQ(loaded.place.selection, PlaceRecognitionConfig::Selection::kFirstVerified);
  EXPECT_EQ(loaded.odometry.icp.kernel, RobustKernel::kTukey);
  EXPECT_FALSE(loaded.slam.loop_refinement.refine);
  EXPECT_EQ(loaded.mapping.max_scans_per_submap, 123);
}

TEST(Config, EveryFieldHasADocAndTheDumpShowsUnits) {
  const std::vector<ConfigFieldInfo> fields = DescribeConfig(Config{});
  EXPECT_GT(fields.size(), 100u);
  for (const ConfigFieldInfo& field : fields) {
    EXPECT_FALSE(field.doc.empty()) << field.key;
    EXPECT_EQ(field.value, field.default_value) << field.key;
  }
  const std::string yaml = ConfigToYaml(Config{});
  EXPECT_NE(yaml.find("place:\n"), std::string::npos);
  EXPECT_NE(yaml.find("  ransac:\n    inlier_distance_m: 0.1  # [m] "), std::string::npos);
  EXPECT_NE(yaml.find("    icp:\n"), std::string::npos);
}

TEST(Config, APartialFileChangesOnlyItsKeys) {
  Config config;
  ApplyConfigYaml("place:\n  min_pairs: 12\n  ransac:\n    iterations: 40\n", "my.yaml", config);
  EXPECT_EQ(config.place.min_pairs, 12);
  EXPECT_EQ(config.place.ransac.iterations, 40);
  Config defaults;
  defaults.place.min_pairs = 12;
  defaults.place.ransac.iterations = 40;
  EXPECT_EQ(ConfigKeyValues(config), ConfigKeyValues(defaults));
  Config empty_file;
  ApplyConfigYaml("", "empty.yaml", empty_file);
  EXPECT_EQ(ConfigKeyValues(empty_file), ConfigKeyValues(Config{}));
}

TEST(Config, BadFilesNameFileLineAndKey) {
  EXPECT_EQ(ErrorOfYaml("place:\n  min_pairs: 10\n  nope: 3\n"),
            "my.yaml:3: unknown configuration key 'place.nope'");
  EXPECT_EQ(ErrorOfYaml("mapping:\n  cell_size_m: 0.1\n\n  min_scan_count: four\n"),
            "my.yaml:4: mapping.min_scan_count: 'four' is not an integer");
  EXPECT_EQ(ErrorOfYaml("mapping:\n  cell_size_m: 0.001\n"),
            "my.yaml:2: mapping.cell_size_m: MappingConfig.cell_size_m must lie in [0.01, 10] m "
            "(docs/MAPPING.md)");
  EXPECT_EQ(ErrorOfYaml("mapping:\n  cell_size_m: inf\n"),
            "my.yaml:2: mapping.cell_size_m: 'inf' is not finite");
  EXPECT_EQ(ErrorOfYaml("place:\n  min_gamma: 1.5\n"),
            "my.yaml:2: place.min_gamma: PlaceRecognitionConfig.min_gamma must lie in [0, 1]");
  EXPECT_EQ(ErrorOfYaml("slam:\n  loop_refinement:\n    refine: maybe\n"),
            "my.yaml:3: slam.loop_refinement.refine: 'maybe' is not true or false");
  EXPECT_EQ(ErrorOfYaml("place:\n  selection: best\n"),
            "my.yaml:2: place.selection: 'best' is not one of first_verified | best_score");
  EXPECT_EQ(ErrorOfYaml("place:\n  min_pairs:\n"),
            "my.yaml:2: place.min_pairs: expected a value, found nothing");
  EXPECT_EQ(ErrorOfYaml("place:\n  min_pairs: [1, 2]\n"),
            "my.yaml:2: place.min_pairs: expected a value, found a list");
  EXPECT_EQ(ErrorOfYaml("odometry: 3\n"), "my.yaml:1: unknown configuration key 'odometry'");
  EXPECT_EQ(ErrorOfYaml("- 1\n- 2\n"), "my.yaml:1: the configuration: expected a mapping of keys");
  // Found by fuzzing (tests/fuzz/regressions/config_yaml): a key that is a list or a mapping
  // ended the program with yaml-cpp's bad conversion; an alias of a mapping inside itself
  // recursed until the stack overflowed.
  EXPECT_EQ(ErrorOfYaml("? [a, b]\n: 1\n"),
            "my.yaml:1: the configuration: a key must be a name, found a list");
  EXPECT_EQ(ErrorOfYaml("place:\n  {x: 1}: 2\n"),
            "my.yaml:2: place: a key must be a name, found a mapping");
  EXPECT_EQ(ErrorOfYaml("place: &loop\n  again: *loop\n"),
            "my.yaml:2: place.again: expected a value, found a mapping (not a section of "
            "keyplace dump-config)");
  EXPECT_EQ(ErrorOfYaml("place:\n  ransac: &r\n    iterations: *r\n"),
            "my.yaml:3: place.ransac.iterations: expected a value, found a mapping (not a section "
            "of keyplace dump-config)");
  const std::string malformed = ErrorOfYaml("place:\n  min_pairs: [1, 2\n");
  EXPECT_EQ(malformed.rfind("my.yaml:", 0), 0u) << malformed;
  EXPECT_NE(malformed.find("malformed YAML"), std::string::npos) << malformed;
}

// Issue 31: what yaml-cpp alone let through or reported badly.
TEST(Config, DuplicateKeysSecondDocumentsAndDeepNestingAreRefused) {
  // yaml-cpp resolved a key given twice to one of its values (the last was applied).
  EXPECT_EQ(ErrorOfYaml("place:\n  min_pairs: 4\n  min_pairs: 5\n"),
            "my.yaml:3: the key 'min_pairs' is given twice in one mapping (YAML allows one)");
  EXPECT_EQ(ErrorOfYaml("place:\n  min_pairs: 4\nplace:\n  min_gamma: 0.5\n"),
            "my.yaml:3: the key 'place' is given twice in one mapping (YAML allows one)");
  // A second document was ignored.
  EXPECT_EQ(ErrorOfYaml("place:\n  min_pairs: 4\n---\nplace:\n  min_pairs: 5\n"),
            "my.yaml:4: a second YAML document (after '---'); the file must hold one");
  // yaml-cpp's own message for nesting beyond its limit is "bad file".
  const std::string deep = ErrorOfYaml(std::string(5000, '[') + std::string(5000, ']'));
  EXPECT_EQ(deep.rfind("my.yaml:1: YAML nested too deeply (yaml-cpp stops at ", 0), 0u) << deep;
  // A key of control bytes is shown escaped and bounded.
  const std::string shown = ErrorOfYaml("\"a\\0b" + std::string(500, 'c') + "\": 1\n");
  EXPECT_NE(shown.find("'a\\0bccc"), std::string::npos) << shown;
  EXPECT_LT(shown.size(), 300u) << shown;
}

TEST(Config, AFileIsReadUpToItsLimitNamingFileAndLimit) {
  Config config;
  try {
    ApplyConfigFile("/dev/zero", config);  // formerly 4.2 GB read, then "out of memory"
    FAIL() << "/dev/zero was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()),
              "/dev/zero: larger than 1 MiB, the limit of a configuration file (not read "
              "further; is it the right file?)");
  }
}

TEST(Config, AssignmentsAndFilesReportTheirErrors) {
  Config config;
  ApplyConfigAssignment("slam.graph.loop_reject_sigmas=4", config);
  EXPECT_EQ(config.slam.graph.loop_reject_sigmas, 4.0);
  EXPECT_THROW(ApplyConfigAssignment("min_pairs=3", config), std::invalid_argument);
  EXPECT_THROW(ApplyConfigAssignment("place.min_pairs", config), std::invalid_argument);
  EXPECT_THROW(ApplyConfigAssignment("place.min_pairs=1", config), std::invalid_argument);
  EXPECT_THROW(ApplyConfigAssignment("mapping.cell_size_m=0.001", config), std::invalid_argument);
  EXPECT_THROW(ApplyConfigAssignment("mapping.cell_size_m=inf", config), std::invalid_argument);
  try {
    ApplyConfigFile("/nonexistent/config.yaml", config);
    FAIL() << "a missing file was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/config.yaml"), std::string::npos);
  }
}

TEST(Config, NoNumberFieldTakesInfinityOrNaN) {
  int number_fields = 0;
  int real_fields = 0;
  for (const ConfigFieldInfo& field : DescribeConfig(Config{})) {
    char* end = nullptr;
    std::strtod(field.default_value.c_str(), &end);
    if (field.default_value.empty() || *end != '\0') continue;  // enums, switches, text
    ++number_fields;
    for (const char* value : {"inf", "-inf", "nan", "infinity"}) {
      Config config;
      try {
        ApplyConfigAssignment(field.key + "=" + value, config);
        ADD_FAILURE() << field.key << "=" << value << " was accepted";
      } catch (const std::invalid_argument& error) {
        // A non-integer default marks a number field: refused as not finite, not by a range.
        const bool real = field.default_value.find_first_of(".e") != std::string::npos;
        if (real) {
          EXPECT_NE(std::string(error.what()).find("' is not finite"), std::string::npos)
              << error.what();
          ++real_fields;
        }
      }
    }
  }
  EXPECT_GT(number_fields, 80);
  EXPECT_GT(real_fields, 4 * 40);  // four spellings of about 60 fields with a fractional default
}

TEST(Config, SlamAndLocalizerTakeTheSharedSections) {
  Config config = PresetConfig("paper");
  config.mapping.min_overlap = 0.6;
  config.odometry.local_map_scans = 7;
  config.localization.max_query_scans = 50;
  const SlamConfig slam = ToSlamConfig(config);
  EXPECT_EQ(slam.mapping.min_overlap, 0.6);
  EXPECT_EQ(slam.odometry.local_map_scans, 7);
  EXPECT_EQ(slam.place.selection, PlaceRecognitionConfig::Selection::kFirstVerified);
  const LocalizerConfig localizer = ToLocalizerConfig(config);
  EXPECT_EQ(localizer.max_query_scans, 50);
  EXPECT_EQ(localizer.place.selection, PlaceRecognitionConfig::Selection::kFirstVerified);
  EXPECT_THROW(PresetConfig("fast"), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
