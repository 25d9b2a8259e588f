#pragma once
// keyplace report: the artefacts a report is drawn from, the keyplace commands that make them,
// and running the missing ones (each an ordinary `keyplace ...` run in a child process).

#include <string>
#include <vector>

namespace keyplace::cli {

/// Where a report's inputs are and how much to compute.
struct ReportSettings {
  std::string data_dir;               // the shared data sets (fr079-corrected.log.gz, ...)
  std::string work_dir;               // every intermediate artefact lives here
  std::vector<std::string> datasets;  // lower-case bases: fr079, fr101, intel
  bool quick = false;                 // few queries and small sweep grids (tests, quick looks)
  int threads = 0;                    // --threads of the sweeps (0 = all cores)
};

/// Paths of the inputs and artefacts of one data set (base "fr079", "fr101" or "intel").
struct DatasetFiles {
  std::string base;           // fr079
  std::string name;           // FR079 (the paper's name; raw: name + "_r")
  std::string corrected_log;  // DATA/fr079-corrected.log.gz
  std::string raw_log;        // DATA/fr079-raw.log.gz
  std::string index;          // DATA/fr079-raw-to-corrected.tsv
  std::string relations;      // DATA/fr079.relations (may not exist)
};
DatasetFiles FilesOf(const ReportSettings& settings, const std::string& base);

/// Artefact paths inside the work directory (one place, so the plan and the page agree).
struct ReportArtefacts {
  static std::string Map(const ReportSettings& s, const std::string& base);      // .kpm
  static std::string MapJson(const ReportSettings& s, const std::string& base);  // default map
  static std::string MapPng(const ReportSettings& s, const std::string& base);   // Figs 3-5
  static std::string TableIIJson(const ReportSettings& s, const std::string& base);
  static std::string RawMapJson(const ReportSettings& s, const std::string& base);  // Table VI
  /// localize JSON; `raw` queries from the raw log; preset "default" | "paper".
  static std::string Localize(const ReportSettings& s, const std::string& base, bool raw,
                              const std::string& preset, double lambda_m, int mu);
  /// `mu` 10: the baseline's defaults (mu 10, consensus 9); 5: mu 5 and consensus 5, the setting
  /// that reproduces Tipaldi et al.'s figures (docs/PLACE.md).
  static std::string TipFlirt(const ReportSettings& s, const std::string& base, int mu = 10);
  /// keyplace relocalize JSON and figure; `raw` queries from the raw log (ICP odometry).
  static std::string Relocalize(const ReportSettings& s, const std::string& base, bool raw);
  static std::string RelocalizePng(const ReportSettings& s, const std::string& base, bool raw);
  static std::string Fig8Dir(const ReportSettings& s, const std::string& base);
  /// The --cache directory of the map, localize and relocalize steps: each log's ICP poses and
  /// keypoints, computed by the first step that reads the log.
  static std::string PreparationCache(const ReportSettings& s);
  static std::string Fig9Dir(const ReportSettings& s, const std::string& base,
                             const std::string& preset);
  static std::string SlamDir(const ReportSettings& s, const std::string& base);
  /// The hospital bag (issue 17's check set): DATA/fr-clinic.orig.bag, its relations, and the
  /// directory of its keyplace slam run.
  static std::string HospitalBag(const ReportSettings& s);
  static std::string HospitalRelations(const ReportSettings& s);
  static std::string HospitalSlamDir(const ReportSettings& s);
};

/// One keyplace run of the plan.
struct ReportStep {
  std::string id;                    // unique, file-name safe: "localize-fr079-default-0.05"
  std::string what;                  // what it is for: "Table III, FR079, default preset"
  std::vector<std::string> args;     // arguments after the program name
  std::vector<std::string> needs;    // input files; a missing one skips the step
  std::vector<std::string> outputs;  // files the step writes (their directories are created)
};

/// Every step of a report, in an order where each step's inputs come before it. Steps whose data
/// files are missing are still listed (the runner skips them and says why).
std::vector<ReportStep> PlanReport(const ReportSettings& settings);

/// The command line of a step as a user would type it ("keyplace localize --map ...").
std::string CommandLine(const ReportStep& step);

enum class StepState { kDone, kRan, kFailed, kSkipped };

/// "done" (before this run), "ran", "failed" or "skipped".
std::string StepStateName(StepState state);

struct StepOutcome {
  StepState state = StepState::kSkipped;
  std::string message;  // why skipped / failed (names the missing file or the log file)
  double seconds = 0.0;
};

/// Runs the steps that are not done yet, one after another, with `program` (this keyplace
/// executable) in a child process each; stdout and stderr go to WORK/logs/<id>.log. A step is
/// done when WORK/done/<id>.cmd holds its command line without --threads (written after a
/// successful run), so a step whose options changed runs again and an interrupted report resumes
/// where it stopped. Prints "[k/N] ..." progress lines with the elapsed time on stdout. With
/// `dry_run` nothing runs: steps are reported done or skipped only.
std::vector<StepOutcome> RunSteps(const ReportSettings& settings,
                                  const std::vector<ReportStep>& steps, const std::string& program,
                                  bool dry_run);

}  // namespace keyplace::cli
