#include "report_run.hpp"

#include <chrono>
#include <filesystem>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

#include "io/atomic_file.hpp"
#include "report_context.hpp"
#include "report_page.hpp"

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

// The settings of `options`, with the data sets checked.
ReportSettings SettingsOf(const ReportOptions& options) {
  if (options.data_dir.empty()) throw std::invalid_argument("report: no data directory");
  ReportSettings settings;
  settings.data_dir = options.data_dir;
  settings.work_dir =
      options.work_dir.empty() ? (fs::path(options.out_dir) / "work").string() : options.work_dir;
  settings.quick = options.quick;
  settings.threads = options.threads;
  for (const std::string& base : Split(options.datasets)) {
    if (base != "fr079" && base != "fr101" && base != "intel") {
      throw std::invalid_argument("--datasets: unknown data set '" + base +
                                  "' (known: fr079, fr101, intel)");
    }
    settings.datasets.push_back(base);
  }
  if (settings.datasets.empty()) throw std::invalid_argument("--datasets is empty");
  return settings;
}

}  // namespace

ReportSummary RunReport(const ReportOptions& options, const std::string& program) {
  const auto start = std::chrono::steady_clock::now();
  ReportContext context;
  context.settings = SettingsOf(options);
  context.datasets_text = options.datasets;
  context.stability_scan = options.stability_scan;
  fs::create_directories(options.out_dir);
  fs::create_directories(context.settings.work_dir);
  context.figures_dir = (fs::path(options.out_dir) / "figures").string();
  fs::create_directories(context.figures_dir);

  context.steps = PlanReport(context.settings);
  fmt::print("keyplace report: {} steps, data {}, work {}\n", context.steps.size(),
             context.settings.data_dir, context.settings.work_dir);
  context.outcomes = RunSteps(context.settings, context.steps, program, options.no_run);
  const double run_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string page = BuildPage(context, run_seconds);
  ReportSummary summary;
  summary.index_path = (fs::path(options.out_dir) / "index.html").string();
  WriteFileAtomically(summary.index_path, [&](std::ostream& out) { out << page; });
  summary.page_bytes = page.size();
  for (std::size_t i = 0; i < context.outcomes.size(); ++i) {
    const StepOutcome& o = context.outcomes[i];
    summary.failed_steps += o.state == StepState::kFailed;
    ReportStepSummary step;
    step.id = context.steps[i].id;
    step.state = StepStateName(o.state);
    step.command = CommandLine(context.steps[i]);
    step.message = o.message;
    step.seconds = o.seconds;
    summary.steps.push_back(step);
  }
  return summary;
}

}  // namespace keyplace::cli
