#include "common/config_fields.hpp"

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
    table.Double("gain", &Example::gain, "m", "a gain")
        .Int("count", &Example::count, "", "a count")
        .Int("seed", &Example::seed, "", "a seed")
        .Bool("enabled", &Example::enabled, "a switch")
        .Enum("mode", &Example::mode,
              {{Example::Mode::kFast, "fast"}, {Example::Mode::kExact, "exact"}}, "a mode");
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
  EXPECT_EQ(ErrorOf({{"mode", "slow"}}), "Example.mode: 'slow' is not one of fast | exact");
  EXPECT_EQ(ErrorOf({{"seed", "-1"}}), "Example.seed: '-1' is not an integer");
}

struct Outer {
  Example inner;
  double scale_m = 1.0;
};

const ConfigFields<Outer>& OuterFields() {
  static const ConfigFields<Outer> fields = [] {
    ConfigFields<Outer> table("Outer");
    table.Double("scale_m", &Outer::scale_m, "m", "a scale")
        .Nested("inner", &Outer::inner, Fields());
    return table;
  }();
  return fields;
}

TEST(ConfigFields, NestedFieldsCarryTheirPrefixUnitAndDoc) {
  Outer outer;
  OuterFields().Apply({{"inner.count", "9"}, {"inner.mode", "fast"}, {"scale_m", "2.5"}}, outer);
  EXPECT_EQ(outer.inner.count, 9);
  EXPECT_EQ(outer.inner.mode, Example::Mode::kFast);
  EXPECT_EQ(outer.scale_m, 2.5);
  const auto& fields = OuterFields().fields();
  ASSERT_EQ(fields.size(), 6u);
  EXPECT_EQ(fields[1].doc.name, "inner.gain");
  EXPECT_EQ(fields[1].doc.unit, "m");
  EXPECT_EQ(fields[5].doc.doc, "a mode (fast | exact)");
  Outer other;
  try {
    OuterFields().Apply({{"inner.count", "x"}}, other);
    FAIL() << "a bad nested value was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "Outer.inner.count: 'x' is not an integer");
  }
}

}  // namespace
}  // namespace keyplace
