// Figures 6 and 7 of the paper drawn from a submap of the bundled corrected FR079 log: the summary
// numbers the figures state (values of the code that drew them first) and the PNGs themselves.

#include "stability_figures.hpp"

#include <cairo.h>

#include <cstddef>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace::cli {
namespace {

std::string BundledLog() { return testing::SourceDir() + "/data/fr079-corrected.log.gz"; }

// Both figures from scan 100, drawn once for all tests.
struct Drawn {
  std::string fig6;
  std::string fig7;
  StabilityFigureSummary summary;
};

const Drawn& FiguresFromScan100() {
  static const Drawn drawn = [] {
    const std::string dir = testing::MakeTempDir("keyplace-stability-figures");
    Drawn d;
    d.fig6 = dir + "/fig6.png";
    d.fig7 = dir + "/fig7.png";
    d.summary = DrawStabilityFigures(BundledLog(), 100, d.fig6, d.fig7);
    return d;
  }();
  return drawn;
}

using Image = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

Image ReadPng(const std::string& path) {
  return Image(cairo_image_surface_create_from_png(path.c_str()), &cairo_surface_destroy);
}

// Pixels of the square panel at x0 (the figures' panels: 560 px, 40 px below the top) whose colour
// passes `test` (red, green, blue in 0..255).
template <typename Test>
int CountPanelPixels(cairo_surface_t* image, int x0, Test test) {
  const unsigned char* data = cairo_image_surface_get_data(image);
  const std::ptrdiff_t stride = cairo_image_surface_get_stride(image);
  int count = 0;
  for (std::ptrdiff_t y = 40; y < 40 + 560; ++y) {
    for (std::ptrdiff_t x = x0; x < x0 + 560; ++x) {
      // B, G, R, X: the words of RGB24/ARGB32 in little-endian byte order.
      const unsigned char* p = data + y * stride + 4 * x;
      if (test(p[2], p[1], p[0])) ++count;
    }
  }
  return count;
}

bool Red(int r, int g, int b) { return r > 200 && g < 60 && b < 60; }
bool Blue(int r, int g, int b) { return b > 200 && r < 60 && g < 120; }

TEST(DrawStabilityFigures, SummaryOfTheSubmapFromScan100) {
  const StabilityFigureSummary& s = FiguresFromScan100().summary;
  EXPECT_EQ(s.dataset, "fr079-corrected.log.gz");
  EXPECT_EQ(s.first_scan, 100);
  EXPECT_EQ(s.last_scan, 112);
  EXPECT_EQ(s.scans, 13u);
  EXPECT_EQ(s.keypoints_first, 32u);
  EXPECT_EQ(s.keypoints_last, 31u);
  EXPECT_EQ(s.history_cells, 184u);
  EXPECT_EQ(s.stable, 35u);
  EXPECT_EQ(s.same_cluster_cells, 3u);
  EXPECT_EQ(s.other_cluster_cells, 1u);
  EXPECT_DOUBLE_EQ(s.min_stability, 0.3);
  EXPECT_NEAR(s.distribution, 0.359578501565544, 1e-9);
  EXPECT_NEAR(s.overlap, 0.748728813559322, 1e-9);
}

TEST(DrawStabilityFigures, WritesBothFiguresWithTheirPanels) {
  const Drawn& drawn = FiguresFromScan100();
  for (const std::string& path : {drawn.fig6, drawn.fig7}) {
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    EXPECT_GT(std::filesystem::file_size(path), 10000u) << path;
    const Image image = ReadPng(path);
    ASSERT_EQ(cairo_surface_status(image.get()), CAIRO_STATUS_SUCCESS) << path;
    EXPECT_EQ(cairo_image_surface_get_width(image.get()), 2 * 560 + 30) << path;
    EXPECT_EQ(cairo_image_surface_get_height(image.get()), 40 + 560 + 64) << path;
  }
  // Figure 6: (a) scan i in blue, scan j in red; (b) stable cells outlined in red.
  const Image fig6 = ReadPng(drawn.fig6);
  EXPECT_GT(CountPanelPixels(fig6.get(), 10, Blue), 200);
  EXPECT_GT(CountPanelPixels(fig6.get(), 10, Red), 200);
  EXPECT_GT(CountPanelPixels(fig6.get(), 580, Red), 200);
  // Figure 7: on black, (a) the stable keypoints circled in red, (b) the red cells of D.
  const Image fig7 = ReadPng(drawn.fig7);
  const auto black = [](int r, int g, int b) { return r + g + b == 0; };
  EXPECT_GT(CountPanelPixels(fig7.get(), 10, black), 100000);
  EXPECT_GT(CountPanelPixels(fig7.get(), 10, Red), 200);
  EXPECT_GT(CountPanelPixels(fig7.get(), 580, Red), 200);
}

TEST(DrawStabilityFigures, ThrowsWhenNoSubmapCompletes) {
  const std::string dir = testing::MakeTempDir("keyplace-stability-figures");
  std::string message;
  try {
    DrawStabilityFigures(BundledLog(), 1462, dir + "/6.png", dir + "/7.png");
  } catch (const std::invalid_argument& error) {
    message = error.what();
  }
  EXPECT_NE(message.find("fr079-corrected.log.gz: no submap completes from scan 1462"),
            std::string::npos)
      << message;
  EXPECT_FALSE(std::filesystem::exists(dir + "/6.png"));
}

}  // namespace
}  // namespace keyplace::cli
