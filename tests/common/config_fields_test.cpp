#include "keyplace/common/config_fields.hpp"

#include <cstdint>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

struct Example {
  enum class Mode { kFast, kExact };
  double gain = 0.1;
  int count = 3;
  std::uint64_t seed = 7;
  bool enabled = true;
  Mode mode = Mode::kExact;
};

const ConfigFields<Example>& Fields() {
  static const ConfigFields<Example> fields = [] {
    ConfigFields<Example> table("Example");
    table.Double("gain", &Example::gain)
        .Int("count", &Example::count)
        .Int("seed", &Example::seed)
        .Bool("enabled", &Example::enabled)
        .Enum("mode", &Example::mode,
              {{Example::Mode::kFast, "fast"}, {Example::Mode::kExact, "exact"}});
    return table;
  }();
  return fields;
}

std::string ErrorOf(const std::map<std::string, std::string>& values) {
  Example example;
  try {
    Fields().Apply(values, example);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(ConfigFields, TextRoundTripIsExact) {
  Example original;
  original.gain = 0.1 + 0.2;  // not representable in short decimal without care
  original.count = -12;
  original.seed = 18446744073709551615ULL;
  original.enabled = false;
  original.mode = Example::Mode::kFast;
  const auto text = Fields().ToKeyValues(original);
  ASSERT_EQ(text.size(), 5u);
  EXPECT_EQ(text[0].first, "gain");
  EXPECT_EQ(text[4].second, "fast");
  Example parsed;
  Fields().Apply({text.begin(), text.end()}, parsed);
  EXPECT_EQ(parsed.gain, original.gain);
  EXPECT_EQ(parsed.count, original.count);
  EXPECT_EQ(parsed.seed, original.seed);
  EXPECT_EQ(parsed.enabled, original.enabled);
  EXPECT_EQ(parsed.mode, original.mode);
}

TEST(ConfigFields, ErrorsNameStructFieldAndValue) {
  EXPECT_EQ(ErrorOf({{"nope", "1"}}), "Example: unknown key 'nope'");
  EXPECT_EQ(ErrorOf({{"gain", "1.5x"}}), "Example.gain: '1.5x' is not a number");
  EXPECT_EQ(ErrorOf({{"count", "2.5"}}), "Example.count: '2.5' is not an integer");
  EXPECT_EQ(ErrorOf({{"count", ""}}), "Example.count: '' is not an integer");
  EXPECT_EQ(ErrorOf({{"enabled", "yes"}}), "Example.enabled: 'yes' is not true or false");
  EXPECT_EQ(ErrorOf({{"mode", "slow"}}), "Example.mode: 'slow' is not one of fast, exact");
  EXPECT_EQ(ErrorOf({{"seed", "-1"}}), "Example.seed: '-1' is not an integer");
}

}  // namespace
}  // namespace keyplace
