#pragma once
// keyplace report from start to end: plan the steps, run the missing ones, write the page.

#include <cstddef>
#include <string>

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

struct ReportSummary {
  std::string index_path;        // OUT/index.html
  std::size_t page_bytes = 0;    // its size
  std::size_t failed_steps = 0;  // steps that failed (listed on the page)
};

/// Plans the report's steps, runs those not done yet with `program` (this keyplace executable),
/// draws the report's own figures and writes OUT/index.html atomically. Prints the plan and each
/// step's progress on stdout. Throws std::invalid_argument for unknown or no data sets.
ReportSummary RunReport(const ReportOptions& options, const std::string& program);

}  // namespace keyplace::cli
