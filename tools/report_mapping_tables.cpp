// The report's mapping tables: II and VI (map of each log), IX and the loops (the SLAM maps).

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "paper_tables.hpp"
#include "report_tables.hpp"

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using A = ReportArtefacts;

const std::vector<ComparedColumn>& MappingColumns() {
  static const std::vector<ComparedColumn> kColumns{
      {"Compress.", Better::kLower, 0.02, false, 3}, {"#Scans", Better::kNone, 0.2, true, 2},
      {"#Keypoints", Better::kNone, 0.2, true, 2},   {"Distrib.", Better::kLower, 0.02, false, 3},
      {"#Submaps", Better::kNone, 0.2, true, 0},     {"Time (s)", Better::kLower, 0.1, true, 4},
  };
  return kColumns;
}

std::vector<std::optional<double>> MappingValues(const std::optional<Json>& json,
                                                 const std::string& path) {
  return {Number(json, "compression", path),
          Number(json, "scans_per_submap", path),
          Number(json, "keypoints_per_submap", path),
          Number(json, "distribution", path),
          Number(json, "submaps", path),
          Number(json, "seconds_per_submap", path)};
}

std::vector<std::optional<double>> PaperMappingValues(const std::string& dataset) {
  const PaperMappingRow* row = PaperMapping(dataset);
  if (row == nullptr) return {};
  return {row->compression,
          row->scans_per_submap,
          row->keypoints_per_submap,
          row->distribution,
          static_cast<double>(row->submaps),
          row->seconds_per_submap};
}

const std::vector<ComparedColumn>& LoopColumns() {
  static const std::vector<ComparedColumn> kColumns{
      {"loops detected", Better::kNone, 0.2, true, 0},
      {"loops used", Better::kNone, 0.2, true, 0},
      {"precision @10 %", Better::kHigher, 0.02, false, 3},
      {"precision @30 %", Better::kHigher, 0.02, false, 3},
      {"@30 % in common area", Better::kHigher, 0.02, false, 3},
      {"precision vs truth", Better::kHigher, 0.02, false, 3},
      {"ATE RMSE (m)", Better::kLower, 0.1, true, 3},
  };
  return kColumns;
}

// Table IX's group of one raw log: the paper's mapping criteria of its SLAM map and ours.
ComparedGroup SlamMappingGroup(const ReportContext& context, const std::string& name,
                               const std::string& path) {
  ComparedGroup group{name, {}, {}};
  if (const PaperSlamRow* p = PaperSlam(name)) {
    group.paper = {p->compression,
                   p->scans_per_submap,
                   p->keypoints_per_submap,
                   p->distribution,
                   static_cast<double>(p->submaps),
                   p->seconds_per_submap};
  }
  group.ours.push_back(
      Row(context, "keyplace slam", path, [&](const auto& j) { return MappingValues(j, path); }));
  return group;
}

// The loops' group of one raw log.
ComparedGroup LoopGroup(const ReportContext& context, const std::string& name,
                        const std::string& path) {
  ComparedGroup group{name, {}, {}};
  if (const PaperSlamRow* p = PaperSlam(name)) {
    group.paper = {static_cast<double>(p->loops_detected),
                   static_cast<double>(p->loops_used),
                   p->precision_overlap_10,
                   p->precision_overlap_30,
                   std::nullopt,
                   std::nullopt,
                   std::nullopt};
  }
  group.ours.push_back(Row(context, "keyplace slam", path, [&](const auto& j) {
    return std::vector<std::optional<double>>{Number(j, "loops_detected", path),
                                              Number(j, "loops_used", path),
                                              Number(j, "precision_overlap_10", path),
                                              Number(j, "precision_overlap_30", path),
                                              Number(j, "precision_overlap_30_common_area", path),
                                              Number(j, "precision_truth", path),
                                              Number(j, "ate_rmse_m", path)};
  }));
  return group;
}

}  // namespace

std::string TableII(const ReportContext& context) {
  std::vector<ComparedGroup> groups;
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    ComparedGroup group{f.name, PaperMappingValues(f.name), {}};
    const std::string t2 = A::TableIIJson(context.settings, base);
    group.ours.push_back(Row(context, "keyplace, overlap criterion only (as Table II)", t2,
                             [&](const auto& j) { return MappingValues(j, t2); }));
    const std::string all = A::MapJson(context.settings, base);
    group.ours.push_back(Row(context, "keyplace, all criteria (the localization map)", all,
                             [&](const auto& j) { return MappingValues(j, all); }));
    groups.push_back(std::move(group));
  }
  return ComparisonTableHtml(
      "table2", "Table II — mapping criteria, corrected logs and poses",
      "Compress. = stable keypoints in the map / FLIRT keypoints of all scans; #Scans, "
      "#Keypoints = mean per submap; Distrib. = mean δ; Time = seconds per submap including "
      "FLIRT extraction and poses (the paper: Intel i3-3217U).",
      MappingColumns(), groups);
}

std::string TableVI(const ReportContext& context) {
  std::vector<ComparedGroup> groups;
  for (const std::string& base : context.settings.datasets) {
    const DatasetFiles f = FilesOf(context.settings, base);
    ComparedGroup group{f.name + "_r", PaperMappingValues(f.name + "_r"), {}};
    const std::string path = A::RawMapJson(context.settings, base);
    group.ours.push_back(Row(context, "keyplace, ICP poses, all criteria", path,
                             [&](const auto& j) { return MappingValues(j, path); }));
    groups.push_back(std::move(group));
  }
  return ComparisonTableHtml("table6", "Table VI — mapping criteria, raw logs (ICP poses)",
                             "Columns as Table II.", MappingColumns(), groups);
}

std::string TableIX(const ReportContext& context) {
  std::vector<ComparedGroup> mapping_groups;
  std::vector<ComparedGroup> loop_groups;
  for (const std::string& base : context.settings.datasets) {
    const std::string name = FilesOf(context.settings, base).name + "_r";
    const std::string path = fs::path(A::SlamDir(context.settings, base)) / "slam.json";
    mapping_groups.push_back(SlamMappingGroup(context, name, path));
    loop_groups.push_back(LoopGroup(context, name, path));
  }
  std::string html =
      ComparisonTableHtml("table9", "Table IX — mapping criteria of the SLAM maps (raw logs)",
                          "Columns as Table II; time = seconds per submap of the whole SLAM run.",
                          MappingColumns(), mapping_groups);
  html += ComparisonTableHtml(
      "loops", "Loops (Section 6.2.2)",
      "Precision @x % = share of detected loops whose matched submaps overlap by at least x % "
      "(IoU of 0.1 m hit cells); in common area = the same IoU counted only over the cells both "
      "submaps observed (docs/SLAM.md); vs truth = loops within 0.5 m / 10° of the corrected "
      "poses, for the loops whose submap origins lie within 50 scans of a corrected scan (the "
      "paper has neither figure). ATE after SE(2) alignment (the paper gives it as Figure 12 "
      "only).",
      LoopColumns(), loop_groups);
  return html;
}

}  // namespace keyplace::cli
