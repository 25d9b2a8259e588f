// keyplace report --out DIR: every figure and table of the paper, ours beside the paper's, in one
// self-contained HTML page. Missing artefacts are made by running keyplace's own commands
// (keyplace_tools: report_run.hpp).

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "report_run.hpp"

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;

std::string DefaultDataDir() {
  const char* shared = std::getenv("KEYPLACE_SHARED");
  return shared != nullptr ? (fs::path(shared) / "data").string() : std::string("../shared/data");
}

// The files of the data directory: the logs and relation files the report reads, which --json
// must not replace.
std::vector<std::string> DataFiles(const std::string& data_dir) {
  std::vector<std::string> files;
  std::error_code error;
  for (fs::directory_iterator entry(data_dir, error), end; !error && entry != end;
       entry.increment(error)) {
    files.push_back(entry->path().string());
  }
  return files;
}

// --json: what the report ran and where the page is.
nlohmann::json ReportJson(const ReportOptions& options, const ReportSummary& summary) {
  nlohmann::json json;
  json["index"] = summary.index_path;
  json["page_bytes"] = summary.page_bytes;
  json["data"] = options.data_dir;
  json["work"] =
      options.work_dir.empty() ? (fs::path(options.out_dir) / "work").string() : options.work_dir;
  json["datasets"] = options.datasets;
  json["quick"] = options.quick;
  json["no_run"] = options.no_run;
  std::map<std::string, std::size_t> counts = {
      {"done", 0}, {"ran", 0}, {"failed", 0}, {"skipped", 0}};
  nlohmann::json steps = nlohmann::json::array();
  for (const ReportStepSummary& step : summary.steps) {
    ++counts[step.state];
    steps.push_back({{"id", step.id},
                     {"state", step.state},
                     {"command", step.command},
                     {"message", step.message},
                     {"seconds", step.seconds}});
  }
  json["steps_total"] = summary.steps.size();
  json["steps_done_before"] = counts["done"];
  json["steps_ran"] = counts["ran"];
  json["steps_failed"] = counts["failed"];
  json["steps_skipped"] = counts["skipped"];
  json["steps"] = steps;
  return json;
}

int Report(const CLI::App& command, ReportOptions options, const std::string& json_path) {
  const auto start = std::chrono::steady_clock::now();
  if (options.data_dir.empty()) options.data_dir = DefaultDataDir();
  CheckOutputs(command, {{"--json", json_path}}, DataFiles(options.data_dir));
  CheckNotReserved("--json", json_path, {options.out_dir + "/index.html"}, "the report's page");
  // This very executable, even if its file is replaced by a rebuild while the report runs.
  const ReportSummary summary = RunReport(options, "/proc/self/exe");
  fmt::print(
      "report written to {} ({:.1f} MB) in {:.0f} s{}\n", summary.index_path,
      static_cast<double>(summary.page_bytes) / 1e6,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
      summary.failed_steps > 0
          ? fmt::format("; {} step(s) FAILED, see the page's command list", summary.failed_steps)
          : "");
  if (!json_path.empty()) {
    nlohmann::json json = ReportJson(options, summary);
    json["seconds_total"] = SecondsSince(start);
    WriteJson(json_path, json);
  }
  return summary.failed_steps > 0 ? 1 : 0;
}

}  // namespace

void RegisterReportCommand(CLI::App& app) {
  auto options = std::make_shared<ReportOptions>();
  auto json_path = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "report",
      "Write DIR/index.html: one self-contained page with every figure (3-12) and table (II-X) "
      "of the paper, ours beside the paper's with the differences highlighted, and beyond it "
      "the kidnapped robot, SLAM on the hospital bag and query time against map size (FR079 "
      "among up to 100 000 submaps copied from the other data sets). Artefacts (maps, "
      "localize/slam JSON, sweeps) are cached in a work directory; missing ones are made by "
      "running keyplace map/localize/sweep/slam, each command listed on the page. Rerun to "
      "resume.");
  command->add_option("--out", options->out_dir, "Output directory (index.html, figures/)")
      ->required();
  command->add_option("--data", options->data_dir,
                      "Data sets directory (default: $KEYPLACE_SHARED/data, else ../shared/data)");
  command->add_option("--json", *json_path,
                      "Write what the report did as JSON to FILE: the page, and every step with "
                      "its command and state (done before, ran, failed, skipped)");
  command->add_option("--work", options->work_dir,
                      "Work directory for artefacts (default OUT/work)");
  command
      ->add_option("--datasets", options->datasets,
                   "Comma-separated data sets: fr079, fr101, intel (each corrected and raw)")
      ->capture_default_str();
  command->add_flag("--no-run", options->no_run,
                    "Run nothing: render what the work directory holds, mark the rest "
                    "\"not computed\"");
  command->add_flag("--quick", options->quick,
                    "20 queries instead of 500 and small sweep grids (tests, a first look)");
  command
      ->add_option("--threads", options->threads,
                   "Threads of the sweeps, localize and relocalize steps (0 = all cores)")
      ->capture_default_str();
  command
      ->add_option("--stability-scan", options->stability_scan,
                   "First scan of the submap drawn in Figures 6-7")
      ->capture_default_str();
  command->callback([command, options, json_path] {
    const int status = Report(*command, *options, *json_path);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace keyplace::cli
