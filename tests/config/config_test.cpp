#include "keyplace/config/config.hpp"
#include "keyplace/config/essential_settings.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "config/spelling.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

using testing::ExpectContains;

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

// dump-config without --all: the essential settings and the changed ones, still a file that gives
// the configuration back on the defaults (a preset's differences included).
TEST(Config, TheEssentialDumpGivesTheConfigurationBackForEveryPreset) {
  for (const std::string& preset : ConfigPresetNames()) {
    Config original = PresetConfig(preset);
    original.place.ransac.iterations = 40;  // not essential, changed: must be in the dump
    const std::string yaml = EssentialConfigToYaml(original);
    Config loaded;
    ApplyConfigYaml(yaml, "dump", loaded);
    EXPECT_EQ(ConfigKeyValues(loaded), ConfigKeyValues(original)) << preset;
    EXPECT_NE(yaml.find("    iterations: 40  # "), std::string::npos) << preset;
  }
}

TEST(Config, TheEssentialDumpOfTheDefaultsHoldsTheEssentialKeysOnly) {
  const std::vector<std::string>& essential = EssentialConfigKeys();
  EXPECT_GE(essential.size(), 10U);
  EXPECT_LE(essential.size(), 20U);
  std::vector<std::string> keys;
  for (const auto& [key, value] : ConfigKeyValues(Config{})) keys.push_back(key);
  std::size_t last_position = 0;
  for (const std::string& key : essential) {
    const auto at = std::find(keys.begin(), keys.end(), key);
    ASSERT_NE(at, keys.end()) << key << " is no configuration key";
    const auto position = static_cast<std::size_t>(at - keys.begin());
    EXPECT_GE(position, last_position) << key << ": not in the field table's order";
    last_position = position;
  }
  const std::string yaml = EssentialConfigToYaml(Config{});
  std::size_t fields = 0;  // lines "key: value  # doc"
  for (std::size_t at = yaml.find("  # "); at != std::string::npos;
       at = yaml.find("  # ", at + 1)) {
    ++fields;
  }
  EXPECT_EQ(fields, essential.size()) << yaml;
  EXPECT_NE(yaml.find("  min_stability: 0.3  # "), std::string::npos);
  EXPECT_EQ(yaml.find("iterations:"), std::string::npos);
  ExpectContains(yaml, std::to_string(keys.size() - essential.size()) +
                           " more settings at their defaults: keyplace dump-config --all");
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
  EXPECT_EQ(ErrorOfYaml("odometry: 3\n"),
            "my.yaml:1: unknown configuration key 'odometry'; did you mean 'node.odometry'?");
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
  // yaml-cpp's LoadAll returned empty documents at one place without end on this input (20 s,
  // then std::bad_alloc; the config_yaml fuzzer).
  EXPECT_EQ(ErrorOfYaml(" ,a,[ ,\xe8"
                        "cel"),
            "my.yaml:1: malformed YAML: the parser makes no progress from here");
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

// Settings valid only together (min_range_m must stay below max_range_m, default 30 m): raising
// both past the old maximum passes in either order, from --set assignments and within a file, and
// is validated once, after the last.
TEST(ConfigBuilder, SettingsThatDependOnEachOtherPassInEitherOrder) {
  for (const bool min_first : {true, false}) {
    ConfigBuilder builder;
    if (min_first) {
      builder.Assign("odometry.min_range_m=40").Assign("odometry.max_range_m=60");
    } else {
      builder.Assign("odometry.max_range_m=60").Assign("odometry.min_range_m=40");
    }
    const Config config = builder.Build();
    EXPECT_EQ(config.odometry.min_range_m, 40.0) << min_first;
    EXPECT_EQ(config.odometry.max_range_m, 60.0) << min_first;
  }
  for (const std::string yaml : {"odometry:\n  min_range_m: 40\n  max_range_m: 60\n",
                                 "odometry:\n  max_range_m: 60\n  min_range_m: 40\n"}) {
    Config config;
    ApplyConfigYaml(yaml, "my.yaml", config);
    EXPECT_EQ(config.odometry.min_range_m, 40.0) << yaml;
    EXPECT_EQ(config.odometry.max_range_m, 60.0) << yaml;
  }
  // A file and a later --set: the file alone would be invalid (40 above the default 30 m).
  const Config config = ConfigBuilder()
                            .Yaml("odometry:\n  min_range_m: 40\n", "my.yaml")
                            .Assign("odometry.max_range_m=60")
                            .Build();
  EXPECT_EQ(config.odometry.max_range_m, 60.0);
}

TEST(ConfigBuilder, AnInvalidSectionNamesTheSettingsGivenToItAndWhere) {
  try {
    ConfigBuilder()
        .Yaml("odometry:\n  max_range_m: 60\n", "my.yaml")
        .Assign("odometry.min_range_m=70")
        .Build();
    FAIL() << "min_range_m above max_range_m was accepted";
  } catch (const std::invalid_argument& error) {
    const std::string text = error.what();
    EXPECT_NE(text.find("max_range_m must be > min_range_m"), std::string::npos) << text;
    EXPECT_NE(text.find("odometry.max_range_m=60 from my.yaml:2"), std::string::npos) << text;
    EXPECT_NE(text.find("odometry.min_range_m=70 from --set"), std::string::npos) << text;
  }
  // One setting: named as a wrong type is, origin first; the same key twice counts once.
  try {
    ConfigBuilder().Assign("mapping.min_overlap=0.5").Assign("mapping.min_overlap=1.5").Build();
    FAIL() << "min_overlap 1.5 was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("--set: mapping.min_overlap: ", 0), 0u)
        << error.what();
  }
  // Unknown keys and wrong types are refused at once, with their origin.
  EXPECT_THROW(ConfigBuilder().Assign("odometry.nope=1"), std::invalid_argument);
  try {
    ConfigBuilder().Set("place.min_pairs", "x", "here");
    FAIL() << "a text for an integer was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()), "here: place.min_pairs: 'x' is not an integer");
  }
}

// "Did you mean": swapped neighbours count one edit; a key in the wrong section finds its own; a
// short name within one edit only (no guess for 'place.nope'); at most three names.
TEST(ConfigBuilder, UnknownKeysNameTheClosestKeys) {
  EXPECT_EQ(EditDistance("mpa", "map"), 1u);
  EXPECT_EQ(EditDistance("odometry.max_rang_m", "odometry.max_range_m"), 1u);
  EXPECT_EQ(EditDistance("", "abc"), 3u);
  EXPECT_EQ(EditDistance("abc", ""), 3u);
  EXPECT_EQ(EditDistance("abcdef", "abdcef"), 1u);
  EXPECT_EQ(EditDistance("ca", "abc"), 3u);  // optimal string alignment: no edit of a swapped pair
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  // A hostile key of 200 kB: no guess from a name far shorter, the right key by its last part.
  const std::string long_section(200000, 'x');
  std::vector<std::string> keys;
  for (const auto& key_value : ConfigKeyValues(Config{})) keys.push_back(key_value.first);
  EXPECT_EQ(DidYouMean(long_section, keys), "");
  EXPECT_EQ(ClosestNames(long_section + ".max_range_m", keys),
            (std::vector<std::string>{"odometry.max_range_m", "slam.loop_refinement.max_range_m"}));
  EXPECT_EQ(DidYouMean("mpa", {"map", "merge", "info"}), "; did you mean 'map'?");
  EXPECT_EQ(DidYouMean("zzzz", {"map", "merge", "info"}), "");
  try {
    ConfigBuilder().Set("place.min_overlap", "0.5", "--set");
    FAIL() << "a key of another section was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()),
              "--set: unknown configuration key 'place.min_overlap'; did you mean "
              "'mapping.min_overlap'?");
  }
  EXPECT_EQ(ErrorOfYaml("odometry:\n  max_rang_m: 60\n"),
            "my.yaml:2: unknown configuration key 'odometry.max_rang_m'; did you mean "
            "'odometry.max_range_m'?");
  EXPECT_LE(ClosestNames("odometry.icp.x",
                         {"odometry.icp.a", "odometry.icp.b", "odometry.icp.c", "odometry.icp.d"})
                .size(),
            3u);
}

// odometry.sparse_normals_from_map and odometry.odometry_prior with its sigmas were removed
// (measured worse, docs/REGISTRATION.md): maps and dumps that record them at their old defaults
// still load, turned on they are refused with the reason, and no key of the table names them.
TEST(ConfigBuilder, RemovedOptionsLoadAtTheirOldDefaultAndAreRefusedOn) {
  Config config;
  ApplyConfigYaml(
      "odometry:\n  sparse_normals_from_map: false\n  odometry_prior: false\n"
      "  prior_point_sigma_m: 0.05\n  prior_sigma_base_m: 0.03\n  prior_sigma_per_m: 0.1\n"
      "  prior_sigma_base_rad: 0.05\n  prior_sigma_per_rad: 0.3\n  prior_sigma_rad_per_m: 0.1\n",
      "old-map.yaml", config);
  EXPECT_EQ(ConfigKeyValues(config), ConfigKeyValues(Config{}));
  for (const std::string key : {"odometry.sparse_normals_from_map", "odometry.odometry_prior"}) {
    try {
      ConfigBuilder().Set(key, "true", "old.yaml:4");
      FAIL() << key << " turned on was accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_EQ(std::string(error.what()).rfind("old.yaml:4: " + key + " was removed", 0), 0u)
          << error.what();
    }
  }
  for (const auto& [key, value] : ConfigKeyValues(Config{})) {
    EXPECT_EQ(key.find("prior"), std::string::npos) << key;
    EXPECT_EQ(key.find("sparse_normals"), std::string::npos) << key;
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
