// Synthetic tests of the FLIRT detector, descriptor and distance.

#include <cmath>
#include <iterator>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/features/descriptor.hpp"
#include "keyplace/features/flirt.hpp"

namespace keyplace {
namespace {

constexpr double kMaxRange = 50.0;

// A 180-degree scan (0.5 deg steps, first beam at -90 deg) of the walls x = 4 and y = 2 seen
// from the origin: one convex corner at (4, 2).
LaserScan CornerScan(double angle_offset_rad = 0.0) {
  LaserScan scan;
  scan.max_range_m = kMaxRange;
  for (int i = 0; i < 360; ++i) {
    const double angle = -M_PI / 2 + i * M_PI / 360;
    double range = 4.0 / std::cos(angle);
    if (std::sin(angle) > 0.0) range = std::min(range, 2.0 / std::sin(angle));
    if (!(range > 0.0) || range > 60.0) range = 81.91;  // no echo
    scan.angles_rad.push_back(angle + angle_offset_rad);
    scan.ranges_m.push_back(std::round(range * 100.0) / 100.0);  // centimetre ranges
    scan.valid.push_back(scan.ranges_m.back() < kMaxRange ? 1 : 0);
  }
  return scan;
}

// What every keypoint of `scan` must satisfy, whatever its invalid beams: it sits on a valid
// beam (finite range in [0, max_range_m)), at that beam's endpoint, with a finite orientation
// and scale and a normalised descriptor (no NaN leaks in from the invalid beams).
void ExpectOnValidBeams(const LaserScan& scan, const std::vector<Keypoint>& keypoints) {
  for (const Keypoint& k : keypoints) {
    ASSERT_GE(k.beam_index, 0);
    ASSERT_LT(k.beam_index, static_cast<int>(scan.size()));
    const double range = scan.ranges_m[k.beam_index];
    EXPECT_TRUE(std::isfinite(range) && range >= 0.0 && range < scan.max_range_m)
        << "keypoint on beam " << k.beam_index << " of range " << range;
    EXPECT_TRUE(k.position_m.allFinite()) << "beam " << k.beam_index;
    EXPECT_NEAR(k.position_m.norm(), range, 1e-9);
    EXPECT_TRUE(std::isfinite(k.orientation_rad));
    EXPECT_TRUE(std::isfinite(k.scale_m));
    double sum = 0.0;
    for (const float v : k.descriptor) {
      EXPECT_TRUE(std::isfinite(v));
      sum += v;
    }
    EXPECT_NEAR(sum, 1.0, 1e-5);
  }
}

BetaGridDescriptor Uniform() {
  BetaGridDescriptor d;
  d.fill(1.0f / kBetaGridBins);
  return d;
}

TEST(SymmetricChi2, ZeroForIdenticalAndSymmetric) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int trial = 0; trial < 20; ++trial) {
    BetaGridDescriptor a, b;
    for (int i = 0; i < kBetaGridBins; ++i) {
      a[i] = uniform(rng);
      b[i] = i % 5 == 0 ? 0.0f : uniform(rng);
    }
    EXPECT_EQ(SymmetricChi2(a, a), 0.0);
    EXPECT_EQ(SymmetricChi2(a, b), SymmetricChi2(b, a));
    EXPECT_GT(SymmetricChi2(a, b), 0.0);
  }
}

TEST(SymmetricChi2, HandComputedCase) {
  BetaGridDescriptor a{}, b{};
  a[0] = 0.5f;
  a[1] = 0.5f;
  b[0] = 1.0f;
  // 0.5 * [(0.5 - 1)^2 / 1.5 + (0.5 - 0)^2 / 0.5], empty bins contribute nothing.
  EXPECT_NEAR(SymmetricChi2(a, b), 0.5 * (0.25 / 1.5 + 0.5), 1e-12);
  // Disjoint normalised histograms are at the maximal distance 1.
  BetaGridDescriptor c{};
  c[47] = 1.0f;
  EXPECT_NEAR(SymmetricChi2(b, c), 1.0, 1e-12);
  EXPECT_NEAR(SymmetricChi2(Uniform(), Uniform()), 0.0, 1e-15);
}

TEST(SymmetricChi2, EarlyExitAgreesWithFullSum) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int trial = 0; trial < 200; ++trial) {
    BetaGridDescriptor a, b;
    for (int i = 0; i < kBetaGridBins; ++i) {
      a[i] = uniform(rng) / kBetaGridBins;
      b[i] = uniform(rng) / kBetaGridBins;
    }
    const double d = SymmetricChi2(a, b);
    for (const double threshold : {0.0, 0.5 * d, d, std::nextafter(d, 1.0), 2.0 * d, 1.0}) {
      EXPECT_EQ(SymmetricChi2Below(a, b, threshold), d < threshold) << d << " " << threshold;
    }
  }
}

// The distance, term by term and in bin order, as FLIRTLib writes it (empty bins replaced by the
// smallest normal double): the packed terms of descriptor.cpp must give its sums bit for bit, or
// pairs at the threshold and the order of equal pairs would change.
double ScalarSymmetricChi2(const BetaGridDescriptor& a, const BetaGridDescriptor& b) {
  constexpr double kZero = std::numeric_limits<double>::min();
  double sum = 0.0;
  for (int i = 0; i < kBetaGridBins; ++i) {
    const double q = a[i] > 0.0f ? static_cast<double>(a[i]) : kZero;
    const double p = b[i] > 0.0f ? static_cast<double>(b[i]) : kZero;
    sum += (q - p) * (q - p) / (q + p);
  }
  return 0.5 * sum;
}

TEST(SymmetricChi2, EqualsTheScalarSumBitForBit) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int trial = 0; trial < 2000; ++trial) {
    BetaGridDescriptor a, b;
    for (int i = 0; i < kBetaGridBins; ++i) {
      // Half-empty, as real descriptors are, with bins of very different sizes.
      a[i] = uniform(rng) < 0.5f ? 0.0f : std::pow(uniform(rng), 4.0f);
      b[i] = uniform(rng) < 0.5f ? 0.0f : std::pow(uniform(rng), 4.0f);
    }
    const double expected = ScalarSymmetricChi2(a, b);
    ASSERT_EQ(SymmetricChi2(a, b), expected) << "trial " << trial;
    // Just above the distance the pair is below, at it not: the early exit stops exactly there.
    ASSERT_EQ(SymmetricChi2IfBelow(a, b, std::nextafter(expected, 10.0)), expected)
        << "trial " << trial;
    ASSERT_TRUE(std::isinf(SymmetricChi2IfBelow(a, b, expected))) << "trial " << trial;
    ASSERT_EQ(SymmetricChi2Below(a, b, std::nextafter(expected, 10.0)), true);
    ASSERT_EQ(SymmetricChi2Below(a, b, expected), false);
  }
}

TEST(FlirtExtractor, CornerYieldsKeypointNearCorner) {
  const LaserScan scan = CornerScan();
  const FlirtExtractor extractor;
  const std::vector<Keypoint> keypoints = extractor.Extract(scan);
  ASSERT_FALSE(keypoints.empty());
  double nearest = std::numeric_limits<double>::infinity();
  for (const Keypoint& k : keypoints) {
    const double to_corner = (k.position_m - Eigen::Vector2d(4.0, 2.0)).norm();
    nearest = std::min(nearest, to_corner);
    EXPECT_LT(to_corner, 0.5);  // the straight walls themselves are not interesting
    EXPECT_NEAR(k.scale_m, 2.0 * extractor.SigmaM(k.scale_level), 1e-12);
    EXPECT_GE(k.beam_index, 0);
    EXPECT_LT(k.beam_index, static_cast<int>(scan.size()));
    // The keypoint is the endpoint of its beam.
    EXPECT_NEAR(k.position_m.norm(), scan.ranges_m[k.beam_index], 1e-9);
  }
  EXPECT_LT(nearest, 0.1);
}

TEST(FlirtExtractor, DescriptorsAreNormalisedHistograms) {
  const FlirtExtractor extractor;
  const std::vector<Keypoint> keypoints = extractor.Extract(CornerScan());
  ASSERT_FALSE(keypoints.empty());
  for (const Keypoint& k : keypoints) {
    double sum = 0.0;
    for (const float v : k.descriptor) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, 1.0f);
      sum += v;
    }
    EXPECT_NEAR(sum, 1.0, 1e-5);
  }
}

TEST(FlirtExtractor, DescriptorSeesTheWalls) {
  // Around the corner point, looking along +x (orientation 0): the cells straight ahead lie
  // behind the wall (only misses or untouched), the cells towards the laser are crossed by
  // rays (misses); the wall cells get hits. So the histogram is far from uniform.
  const FlirtExtractor extractor;
  const LaserScan scan = CornerScan();
  const BetaGridDescriptor d = extractor.Describe(scan, Eigen::Vector2d(4.0, 0.0), 0.0);
  EXPECT_GT(SymmetricChi2(d, Uniform()), 0.05);
  // The same point described with a different orientation is a rotated histogram.
  const BetaGridDescriptor rotated =
      extractor.Describe(scan, Eigen::Vector2d(4.0, 0.0), M_PI / 6.0);
  EXPECT_GT(SymmetricChi2(d, rotated), 0.01);
}

TEST(FlirtExtractor, RotatingTheScanRotatesTheKeypoints) {
  // Rotating every beam by delta while the world frame stays put (T_world_laser rotated by
  // -delta) leaves FLIRTLib's world-aligned duplicate box unchanged, so the keypoints must
  // rotate exactly with the scan.
  const FlirtExtractor extractor;
  const double delta = 0.3;
  const std::vector<Keypoint> a = extractor.Extract(CornerScan(), Pose2());
  const std::vector<Keypoint> b = extractor.Extract(CornerScan(delta), Pose2(0.0, 0.0, -delta));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_FALSE(a.empty());
  const Pose2 rotation(0.0, 0.0, delta);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].beam_index, b[k].beam_index);
    EXPECT_EQ(a[k].scale_level, b[k].scale_level);
    EXPECT_LT((rotation * a[k].position_m - b[k].position_m).norm(), 1e-9);
    EXPECT_NEAR(WrapAngle(a[k].orientation_rad + delta - b[k].orientation_rad), 0.0, 1e-6);
    EXPECT_LT(SymmetricChi2(a[k].descriptor, b[k].descriptor), 1e-6);
  }
}

TEST(FlirtExtractor, TranslatingTheWorldFrameChangesNothing) {
  const FlirtExtractor extractor;
  const std::vector<Keypoint> a = extractor.Extract(CornerScan(), Pose2());
  const std::vector<Keypoint> b = extractor.Extract(CornerScan(), Pose2(12.5, -3.25, 0.0));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].beam_index, b[k].beam_index);
    EXPECT_NEAR(a[k].orientation_rad, b[k].orientation_rad, 1e-6);
  }
}

TEST(FlirtExtractor, DegenerateScansGiveNoKeypoints) {
  const FlirtExtractor extractor;
  EXPECT_TRUE(extractor.Extract(LaserScan()).empty());

  LaserScan tiny = CornerScan();
  tiny.ranges_m.resize(4);
  tiny.angles_rad.resize(4);
  tiny.valid.resize(4);
  EXPECT_TRUE(extractor.Extract(tiny).empty());

  LaserScan no_echo = CornerScan();
  for (double& r : no_echo.ranges_m) r = 81.91;
  EXPECT_TRUE(extractor.Extract(no_echo).empty());

  // Every beam invalid, as NaN or as any other invalid range: no graph vertex, no keypoint.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  LaserScan all_nan = CornerScan();
  for (double& r : all_nan.ranges_m) r = kNaN;
  LaserScan all_invalid = CornerScan();
  const double invalid_ranges[] = {kNaN, kInf, -kInf, -1.0, kMaxRange, 81.91};
  for (std::size_t i = 0; i < all_invalid.size(); ++i) {
    all_invalid.ranges_m[i] = invalid_ranges[i % std::size(invalid_ranges)];
  }
  for (const LaserScan* scan : {&all_nan, &all_invalid}) {
    std::vector<Keypoint> keypoints{Keypoint{}};
    EXPECT_NO_THROW(keypoints = extractor.Extract(*scan));
    EXPECT_TRUE(keypoints.empty());
    EXPECT_TRUE(extractor.Detect(*scan).empty());
    const FlirtSignals signals = extractor.ComputeSignals(*scan);
    EXPECT_TRUE(signals.beam_of_vertex.empty());
    EXPECT_TRUE(signals.vertices_m.empty());
    EXPECT_TRUE(signals.spanning_trees.empty());
    ASSERT_EQ(signals.peak_vertices.size(),
              static_cast<std::size_t>(extractor.config().num_scales));
    for (const std::vector<int>& peaks : signals.peak_vertices) EXPECT_TRUE(peaks.empty());
  }

  // Only 4 valid beams among NaNs: below the 5 the detector needs, no keypoint.
  LaserScan four_valid = CornerScan();
  for (std::size_t i = 0; i < four_valid.size(); ++i) {
    if (i % 90 != 45) four_valid.ranges_m[i] = kNaN;
  }
  EXPECT_EQ(extractor.ComputeSignals(four_valid).beam_of_vertex,
            (std::vector<int>{45, 135, 225, 315}));
  EXPECT_TRUE(extractor.Extract(four_valid).empty());

  // Every 40th beam kept (8 with an echo; beam 0 has none) among NaNs: the graph holds exactly
  // those, and whatever comes out (none today) lies on them.
  LaserScan broken = CornerScan();
  for (std::size_t i = 0; i < broken.size(); ++i) {
    if (i % 40 != 0) broken.ranges_m[i] = kNaN;
  }
  EXPECT_EQ(extractor.ComputeSignals(broken).beam_of_vertex,
            (std::vector<int>{40, 80, 120, 160, 200, 240, 280, 320}));
  std::vector<Keypoint> broken_keypoints;
  EXPECT_NO_THROW(broken_keypoints = extractor.Extract(broken));
  ExpectOnValidBeams(broken, broken_keypoints);

  LaserScan no_max_range = CornerScan();
  no_max_range.max_range_m = 0.0;
  EXPECT_TRUE(extractor.Extract(no_max_range).empty());

  // A straight wall has no corner: no keypoint far from the scan borders.
  LaserScan wall = CornerScan();
  for (std::size_t i = 0; i < wall.size(); ++i) {
    wall.ranges_m[i] = std::min(81.91, 3.0 / std::cos(wall.angles_rad[i]));
  }
  for (const Keypoint& k : extractor.Extract(wall)) EXPECT_GT(k.position_m.norm(), 5.0);
}

TEST(FlirtExtractor, NanBeamsAreLeftOutAndTheCornerIsStillFound) {
  // Every third beam of the corner scan is NaN (a driver's "no reading"): those beams are not
  // graph vertices, no keypoint lies on one, and the corner is still found. NaN beams weigh in
  // the graph exactly as no-return beams do: the detector signals are identical.
  const FlirtExtractor extractor;
  LaserScan scan = CornerScan();
  LaserScan no_return = CornerScan();
  std::vector<int> valid_beams;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (i % 3 == 1) {
      scan.ranges_m[i] = std::numeric_limits<double>::quiet_NaN();
      no_return.ranges_m[i] = 81.91;
    } else if (scan.ranges_m[i] < kMaxRange) {
      valid_beams.push_back(static_cast<int>(i));
    }
  }
  const FlirtSignals signals = extractor.ComputeSignals(scan);
  EXPECT_EQ(signals.beam_of_vertex, valid_beams);
  const FlirtSignals no_return_signals = extractor.ComputeSignals(no_return);
  EXPECT_EQ(signals.beam_of_vertex, no_return_signals.beam_of_vertex);
  EXPECT_EQ(signals.signal, no_return_signals.signal);
  EXPECT_EQ(signals.peak_vertices, no_return_signals.peak_vertices);
  for (const std::vector<double>& level : signals.signal) {
    for (const double v : level) EXPECT_TRUE(std::isfinite(v));
  }

  const std::vector<Keypoint> keypoints = extractor.Extract(scan);
  ASSERT_FALSE(keypoints.empty());
  ExpectOnValidBeams(scan, keypoints);
  double nearest = std::numeric_limits<double>::infinity();
  for (const Keypoint& k : keypoints) {
    EXPECT_NE(k.beam_index % 3, 1) << "keypoint on NaN beam " << k.beam_index;
    nearest = std::min(nearest, (k.position_m - Eigen::Vector2d(4.0, 2.0)).norm());
  }
  EXPECT_LT(nearest, 0.1);
}

TEST(FlirtExtractor, MismatchedScanThrows) {
  LaserScan scan = CornerScan();
  scan.angles_rad.pop_back();
  EXPECT_THROW(FlirtExtractor().Extract(scan), std::invalid_argument);
}

void ExpectInvalid(void (*mutate)(FlirtConfig&), const std::string& field) {
  FlirtConfig config;
  mutate(config);
  try {
    FlirtExtractor extractor(config);
    ADD_FAILURE() << "no exception for " << field;
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
  }
}

TEST(FlirtConfig, ValidationNamesTheField) {
  EXPECT_NO_THROW(FlirtExtractor(FlirtConfig{}));
  ExpectInvalid([](FlirtConfig& c) { c.num_scales = 0; }, "num_scales");
  ExpectInvalid([](FlirtConfig& c) { c.base_sigma_m = -0.2; }, "base_sigma_m");
  ExpectInvalid([](FlirtConfig& c) { c.sigma_step = std::nan(""); }, "sigma_step");
  ExpectInvalid([](FlirtConfig& c) { c.dmst = -1; }, "dmst");
  ExpectInvalid([](FlirtConfig& c) { c.min_peak = INFINITY; }, "min_peak");
  ExpectInvalid([](FlirtConfig& c) { c.min_peak_difference = -1.0; }, "min_peak_difference");
  ExpectInvalid([](FlirtConfig& c) { c.duplicate_box_m = -0.1; }, "duplicate_box_m");
  ExpectInvalid([](FlirtConfig& c) { c.kernel_cutoff_sigmas = 0.0; }, "kernel_cutoff_sigmas");
  ExpectInvalid([](FlirtConfig& c) { c.descriptor_min_rho_m = -1.0; }, "descriptor_min_rho_m");
  ExpectInvalid([](FlirtConfig& c) { c.descriptor_max_rho_m = 0.01; }, "descriptor_max_rho_m");
  ExpectInvalid([](FlirtConfig& c) { c.descriptor_radial_border_m = -0.05; },
                "descriptor_radial_border_m");
  ExpectInvalid([](FlirtConfig& c) { c.descriptor_angular_border_rad = 1.0; },
                "descriptor_angular_border_rad");
}

}  // namespace
}  // namespace keyplace
