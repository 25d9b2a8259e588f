// Unit tests of the report's plan: the kidnapped robot's steps (keyplace relocalize).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "report_plan.hpp"

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;

ReportSettings Settings(bool quick) {
  ReportSettings settings;
  settings.data_dir = "/data";
  settings.work_dir = "/work";
  settings.datasets = {"fr079", "intel"};
  settings.quick = quick;
  return settings;
}

// The index of the step `id` in `steps` (steps.size() when absent).
std::size_t IndexOf(const std::vector<ReportStep>& steps, const std::string& id) {
  const auto it =
      std::find_if(steps.begin(), steps.end(), [&](const ReportStep& s) { return s.id == id; });
  return static_cast<std::size_t>(it - steps.begin());
}

TEST(ReportPlanTest, RelocalizesTheCorrectedLogAgainstItsOwnMap) {
  const std::vector<ReportStep> steps = PlanReport(Settings(false));
  const std::size_t k = IndexOf(steps, "relocalize-fr079");
  ASSERT_LT(k, steps.size());
  const ReportStep& step = steps[k];
  EXPECT_EQ(CommandLine(step),
            "keyplace relocalize --map /work/maps/fr079.kpm --log /data/fr079-corrected.log.gz "
            "--self-match shared-scan --starts 50 --json /work/relocalize/fr079.json --figure "
            "/work/relocalize/fr079.png");
  EXPECT_EQ(step.needs,
            (std::vector<std::string>{"/work/maps/fr079.kpm", "/data/fr079-corrected.log.gz"}));
  EXPECT_EQ(step.outputs, (std::vector<std::string>{"/work/relocalize/fr079.json",
                                                    "/work/relocalize/fr079.png"}));
  EXPECT_EQ(step.outputs[0], ReportArtefacts::Relocalize(Settings(false), "fr079", false));
  EXPECT_EQ(step.outputs[1], ReportArtefacts::RelocalizePng(Settings(false), "fr079", false));
  // The map it reads is made before it.
  EXPECT_LT(IndexOf(steps, "map-fr079"), k);
}

TEST(ReportPlanTest, RelocalizesTheRawLogWithIcpOdometryAgainstTheCorrectedMap) {
  const std::vector<ReportStep> steps = PlanReport(Settings(false));
  const std::size_t k = IndexOf(steps, "relocalize-intel-raw");
  ASSERT_LT(k, steps.size());
  const ReportStep& step = steps[k];
  EXPECT_EQ(CommandLine(step),
            "keyplace relocalize --map /work/maps/intel.kpm --log /data/intel-raw.log.gz --poses "
            "icp --truth /data/intel-corrected.log.gz --index /data/intel-raw-to-corrected.tsv "
            "--starts 50 --json /work/relocalize/intel-raw.json --figure "
            "/work/relocalize/intel-raw.png");
  EXPECT_EQ(step.needs, (std::vector<std::string>{"/work/maps/intel.kpm", "/data/intel-raw.log.gz",
                                                  "/data/intel-corrected.log.gz",
                                                  "/data/intel-raw-to-corrected.tsv"}));
  EXPECT_EQ(step.outputs, (std::vector<std::string>{"/work/relocalize/intel-raw.json",
                                                    "/work/relocalize/intel-raw.png"}));
  EXPECT_LT(IndexOf(steps, "map-intel"), k);
  // One step of each kind per data set.
  EXPECT_EQ(std::count_if(steps.begin(), steps.end(),
                          [](const ReportStep& s) { return s.args[0] == "relocalize"; }),
            4);
}

TEST(ReportPlanTest, QuickReportsUseFewStarts) {
  for (const ReportStep& step : PlanReport(Settings(true))) {
    if (step.args[0] != "relocalize") continue;
    const auto starts = std::find(step.args.begin(), step.args.end(), "--starts");
    ASSERT_NE(starts, step.args.end()) << step.id;
    ASSERT_NE(starts + 1, step.args.end()) << step.id;
    EXPECT_EQ(*(starts + 1), "6") << step.id;
  }
}

TEST(ReportPlanTest, RelocalizeStepsWithoutDataAreSkipped) {
  const fs::path dir = fs::temp_directory_path() / "keyplace_report_plan_test";
  fs::remove_all(dir);
  ReportSettings settings = Settings(false);
  settings.data_dir = (dir / "data").string();
  settings.work_dir = (dir / "work").string();
  settings.datasets = {"fr079"};
  std::vector<ReportStep> steps;
  for (const ReportStep& step : PlanReport(settings)) {
    if (step.args[0] == "relocalize") steps.push_back(step);
  }
  ASSERT_EQ(steps.size(), 2u);
  const std::vector<StepOutcome> outcomes = RunSteps(settings, steps, "/nonexistent", false);
  for (const StepOutcome& outcome : outcomes) {
    EXPECT_EQ(outcome.state, StepState::kSkipped);
    EXPECT_EQ(outcome.message,
              "needs " + ReportArtefacts::Map(settings, "fr079") + ", which does not exist");
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace keyplace::cli
