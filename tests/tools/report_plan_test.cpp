// Unit tests of the report's plan and of a table drawn from a hand-made artefact: the kidnapped
// robot's steps (keyplace relocalize) and its table.

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "report_context.hpp"
#include "report_hospital.hpp"
#include "report_map_size.hpp"
#include "report_plan.hpp"
#include "report_tables.hpp"

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

// A page builder's context whose data and work directories lie in `dir` (emptied), FR079 only.
ReportContext ContextIn(const fs::path& dir) {
  fs::remove_all(dir);
  ReportContext context;
  context.settings.data_dir = (dir / "data").string();
  context.settings.work_dir = (dir / "work").string();
  context.settings.datasets = {"fr079"};
  return context;
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
            "--self-match shared-scan --starts 50 --threads 0 --cache /work/cache --json "
            "/work/relocalize/fr079.json "
            "--figure "
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
            "--starts 50 --threads 0 --cache /work/cache --json /work/relocalize/intel-raw.json "
            "--figure "
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

TEST(ReportPlanTest, LocalizeAndRelocalizeStepsUseTheReportsThreads) {
  ReportSettings settings = Settings(false);
  settings.threads = 3;
  int steps_with_queries = 0;
  for (const ReportStep& step : PlanReport(settings)) {
    if (step.args[0] != "localize" && step.args[0] != "relocalize") continue;
    if (step.id.rfind("map-size-", 0) == 0) continue;  // one core by definition (below)
    ++steps_with_queries;
    const auto threads = std::find(step.args.begin(), step.args.end(), "--threads");
    ASSERT_NE(threads, step.args.end()) << step.id;
    ASSERT_NE(threads + 1, step.args.end()) << step.id;
    EXPECT_EQ(*(threads + 1), "3") << step.id;
  }
  EXPECT_GT(steps_with_queries, 20);
}

// The raw logs are read by ten steps each: the first one's ICP poses and keypoints serve the rest.
TEST(ReportPlanTest, EveryMapLocalizeAndRelocalizeStepSharesOnePreparationCache) {
  const ReportSettings settings = Settings(false);
  int cached = 0;
  for (const ReportStep& step : PlanReport(settings)) {
    const std::string& command = step.args[0];
    if (command != "map" && command != "localize" && command != "relocalize") continue;
    const auto cache = std::find(step.args.begin(), step.args.end(), "--cache");
    ASSERT_NE(cache, step.args.end()) << step.id;
    ASSERT_NE(cache + 1, step.args.end()) << step.id;
    EXPECT_EQ(*(cache + 1), ReportArtefacts::PreparationCache(settings)) << step.id;
    ++cached;
  }
  EXPECT_GT(cached, 30);
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

TEST(ReportTablesTest, KidnappedRobotTableRendersTheJsonAndNamesWhatIsMissing) {
  const fs::path dir = fs::temp_directory_path() / "keyplace_report_tables_test";
  ReportContext context = ContextIn(dir);
  context.steps = PlanReport(context.settings);
  context.outcomes.resize(context.steps.size());
  const std::string path = ReportArtefacts::Relocalize(context.settings, "fr079", false);
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << R"({"starts": 50, "starts_with_revisit": 31, "fixed_fraction": 0.871,
    "wrong_fixes": 3, "fixes": 412, "wrong_fix_rate": 0.00728, "distance_to_fix_median_m": 4.26,
    "distance_to_fix_p90_m": 17.94, "distance_after_revisit_median_m": 1.35,
    "update_seconds_mean": 0.01234, "update_seconds_max": 0.2, "lost_signals": 5,
    "lost_on_correct_track": 1, "lost_on_wrong_track": 3, "query_log_is_map_log": true,
    "exclude_shared_scans": true})";
  const std::string html = RelocalizationTable(context);
  fs::remove_all(dir);
  EXPECT_NE(html.find("<h3 id=\"relocalize\">Kidnapped robot (keyplace relocalize, strict "
                      "preset)</h3>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<tr><th>FR079</th><td class=\"text\">the map's own log, shared-scan "
                      "exclusion</td><td>50 (31)</td><td>0.871</td><td>3 / 412 (0.0073)</td>"
                      "<td>4.3</td><td>17.9</td><td>1.4</td><td>5 (1 / 3)</td><td>12.34</td></tr>"),
            std::string::npos)
      << html;
  // The raw log's row says how to make it.
  EXPECT_NE(html.find("<tr><th>FR079_r</th><td colspan=\"9\" class=\"missing\">not computed: run "
                      "<code>keyplace relocalize --map "),
            std::string::npos)
      << html;
}

// Issue 17: a full report runs keyplace slam on the hospital bag when the bag and its relations
// are in the data directory, and its section shows the relation error beside the published ones.
TEST(ReportHospitalTest, PlannedWhenTheBagExistsAndRenderedFromItsJson) {
  const fs::path dir = fs::temp_directory_path() / "keyplace_report_hospital_test";
  ReportContext context = ContextIn(dir);
  auto planned = [&](bool quick) {
    ReportSettings settings = context.settings;
    settings.quick = quick;
    const std::vector<ReportStep> steps = PlanReport(settings);
    return IndexOf(steps, "slam-fr-clinic-bag") < steps.size();
  };
  EXPECT_FALSE(planned(false));  // no bag
  fs::create_directories(dir / "data");
  std::ofstream(ReportArtefacts::HospitalBag(context.settings)) << "bag";
  EXPECT_FALSE(planned(false));  // no relations
  std::ofstream(ReportArtefacts::HospitalRelations(context.settings)) << "relations";
  EXPECT_TRUE(planned(false));
  EXPECT_FALSE(planned(true));  // minutes of work: not in a quick report
  context.steps = PlanReport(context.settings);
  context.outcomes.resize(context.steps.size());
  const ReportStep& step = context.steps[IndexOf(context.steps, "slam-fr-clinic-bag")];
  EXPECT_EQ(CommandLine(step),
            "keyplace slam " + (dir / "data/fr-clinic.orig.bag").string() + " --relations " +
                (dir / "data/fr-clinic.relations").string() + " --json " +
                (dir / "work/slam/fr-clinic-bag/slam.json").string() + " --loops " +
                (dir / "work/slam/fr-clinic-bag/loops.tsv").string() + " --figures " +
                (dir / "work/slam/fr-clinic-bag/figures").string());

  // Before the run: a note saying how to make it.
  std::string html = HospitalSection(context);
  EXPECT_NE(html.find("not computed: run <code>keyplace slam "), std::string::npos) << html;
  const fs::path json = dir / "work/slam/fr-clinic-bag/slam.json";
  fs::create_directories(json.parent_path());
  std::ofstream(json) << R"({"loops_detected": 26, "loops_used": 16, "relations": {
    "translation_mean_m": 0.1401, "translation_std_m": 0.2154, "local_translation_mean_m": 0.0837,
    "local_translation_std_m": 0.1066, "loop_translation_mean_m": 0.1902,
    "loop_translation_std_m": 0.2687}})";
  html = HospitalSection(context);
  fs::remove_all(dir);
  EXPECT_NE(html.find("<tr><td>keyplace slam</td><td>26 / 16</td><td>0.140 ± 0.215 m</td>"
                      "<td>0.084 ± 0.107 m</td><td>0.190 ± 0.269 m</td></tr>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("0.143 ± 0.180 m"), std::string::npos);
  // The trajectory figure is missing: its note names the step.
  EXPECT_NE(html.find("not computed: run <code>keyplace slam "), std::string::npos) << html;
}

// Issue 35: FR079 among the other data sets' submaps, both retrievals, on one core; rendered as a
// table with the exact / words ratio and a figure.
TEST(ReportMapSizeTest, PlannedWithDistractorsAndRenderedFromItsJson) {
  const fs::path dir = fs::temp_directory_path() / "keyplace_report_map_size_test";
  ReportContext context = ContextIn(dir);
  context.settings.quick = true;
  EXPECT_TRUE(PlanMapSizeSteps(context.settings).empty());  // no other building to copy
  EXPECT_NE(MapSizeSection(context).find("needs FR079 and at least one other data set"),
            std::string::npos);
  context.settings.datasets = {"fr079", "intel", "fr101"};
  EXPECT_EQ(PlanMapSizeSteps(context.settings).size(), 2u);  // quick: 10^3 submaps
  context.settings.quick = false;
  context.steps = PlanReport(context.settings);
  context.outcomes.resize(context.steps.size());
  const ReportStep& step = context.steps[IndexOf(context.steps, "map-size-words-10000")];
  const std::string command = CommandLine(step);
  EXPECT_NE(command.find("--distractors " + ReportArtefacts::Map(context.settings, "intel") + "," +
                         ReportArtefacts::Map(context.settings, "fr101") +
                         " --distractor-submaps 10000 --n-pos 20 --threads 1 "),
            std::string::npos)
      << command;
  EXPECT_NE(command.find("--set place.retrieval=words --json " +
                         MapSizeJson(context.settings, "words", 10000)),
            std::string::npos)
      << command;
  EXPECT_LT(IndexOf(context.steps, "map-intel"), IndexOf(context.steps, "map-size-exact-1000"));
  const std::vector<std::string> needs{ReportArtefacts::Map(context.settings, "fr079"),
                                       FilesOf(context.settings, "fr079").corrected_log,
                                       ReportArtefacts::Map(context.settings, "intel"),
                                       ReportArtefacts::Map(context.settings, "fr101")};
  EXPECT_EQ(step.needs, needs);
  EXPECT_EQ(step.outputs, std::vector<std::string>{MapSizeJson(context.settings, "words", 10000)});
  // Nothing has run: the table says how, and no empty figure is drawn.
  context.figures_dir = (dir / "figures").string();
  EXPECT_NE(MapSizeSection(context).find("figure: no map-size step has run yet"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "figures/map-size.png"));

  auto write = [&](const std::string& retrieval, int submaps, double seconds, double recall) {
    const std::string path = MapSizeJson(context.settings, retrieval, submaps);
    fs::create_directories(fs::path(path).parent_path());
    std::ofstream(path) << fmt::format(
        R"({{"seconds_per_query_mean": {}, "precision": 1.0, "recall": {},
        "seconds_preparation": 2.5}})",
        seconds, recall);
  };
  write("exact", 1000, 0.096, 0.95);
  write("words", 1000, 0.012, 0.90);
  fs::create_directories(context.figures_dir);
  const std::string html = MapSizeSection(context);
  const bool figure = fs::exists(dir / "figures/map-size.png");
  fs::remove_all(dir);
  EXPECT_NE(html.find("<tr><td>1000</td><td>exact</td><td>96.0</td><td>–</td><td>1.000</td>"
                      "<td>0.950</td><td>2.5</td></tr>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<tr><td>1000</td><td>words</td><td>12.0</td><td>8.0</td><td>1.000</td>"
                      "<td>0.900</td><td>2.5</td></tr>"),
            std::string::npos)
      << html;
  // 10^4 and 10^5 are not computed yet: their rows say how.
  EXPECT_NE(
      html.find(
          "<tr><td>10000</td><td>exact</td><td colspan=\"5\" class=\"missing\">not computed: run "
          "<code>keyplace localize --map "),
      std::string::npos)
      << html;
  EXPECT_TRUE(figure);
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
}

}  // namespace
}  // namespace keyplace::cli
