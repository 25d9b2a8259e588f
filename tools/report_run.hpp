#pragma once
// keyplace report from start to end: plan the steps, run the missing ones, write the page.

#include <cstddef>
#include <string>
#include <vector>

namespace keyplace::cli {

/// What a report is asked for (the options of keyplace report).
struct ReportOptions {
  std::string out_dir;   // index.html and figures/ go here
  std::string data_dir;  // the data sets (fr079-corrected.log.gz, ...); required
  std::string work_dir;  // every intermediate artefact; "" = OUT/work
  std::string datasets = "fr079,fr101,intel";  // comma-separated bases
  bool no_run = false;                         // run nothing, render what the work dir holds
  bool quick = false;                          // few queries and small sweep grids
  int threads = 0;                             // --threads of the sweeps (0 = all cores)
  std::size_t stability_scan = 100;            // first scan of the submap of Figures 6-7
};

/// What became of one step of the plan.
struct ReportStepSummary {
  std::string id;       // ReportStep::id
  std::string state;    // "done" (before this run), "ran", "failed" or "skipped"
  std::string command;  // CommandLine(step)
  std::string message;  // why skipped / failed
  double seconds = 0.0;
};

struct ReportSummary {
  std::string index_path;                // OUT/index.html
  std::size_t page_bytes = 0;            // its size
  std::size_t failed_steps = 0;          // steps that failed (listed on the page)
  std::vector<ReportStepSummary> steps;  // every step of the plan, in order
};

/// Plans the report's steps, runs those not done yet with `program` (this keyplace executable),
/// draws the report's own figures and writes OUT/index.html atomically. Prints the plan and each
/// step's progress on stdout. Throws std::invalid_argument for unknown or no data sets.
ReportSummary RunReport(const ReportOptions& options, const std::string& program);

}  // namespace keyplace::cli
