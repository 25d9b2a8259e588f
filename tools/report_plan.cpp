#include "report_plan.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "io/atomic_file.hpp"
#include "report_map_size.hpp"

extern char** environ;  // NOLINT(readability-redundant-declaration): POSIX, for posix_spawn

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;

std::string Join(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / name).string();
}

std::string LambdaText(double lambda_m) { return fmt::format("{:g}", lambda_m); }

std::string DisplayName(const std::string& base) {
  if (base == "fr079") return "FR079";
  if (base == "fr101") return "FR101";
  if (base == "intel") return "Intel";
  return base;
}

bool Exists(const std::string& path) {
  std::error_code error;
  return fs::exists(path, error);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string Elapsed(double seconds) {
  if (seconds < 60.0) return fmt::format("{:.1f} s", seconds);
  const auto total = static_cast<int>(std::lround(seconds));
  return fmt::format("{} min {:02d} s", total / 60, total % 60);
}

// Runs `program args...` with stdout and stderr appended to `log_path`; returns the exit status
// (or -1 when it could not start, with `error` set).
int Spawn(const std::string& program, const std::vector<std::string>& args,
          const std::string& log_path, std::string& error) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, STDIN_FILENO);
  std::vector<std::string> argv_text{program};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(argv_text.size() + 1);
  for (std::string& arg : argv_text) argv.push_back(arg.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    error = fmt::format("cannot start {}: {}", program, std::strerror(spawned));
    return -1;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      error = fmt::format("waiting for {}: {}", program, std::strerror(errno));
      return -1;
    }
  }
  if (WIFSIGNALED(status)) {
    error = fmt::format("killed by signal {}", WTERMSIG(status));
    return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Quotes an argument for display when the shell would split it.
std::string Quoted(const std::string& arg) {
  if (!arg.empty() && arg.find_first_of(" \t\"'$\\*?;&|<>()") == std::string::npos) return arg;
  std::string out = "'";
  for (const char c : arg) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// What makes a step's result: its command line without --threads and --cache, which change only
// the time (docs/SWEEPS.md; LogInputOptions::cache_dir), so that a report resumed with another
// thread count reuses the sweeps.
std::string Identity(const ReportStep& step) {
  ReportStep copy = step;
  copy.args.clear();
  for (std::size_t i = 0; i < step.args.size(); ++i) {
    if ((step.args[i] == "--threads" || step.args[i] == "--cache") && i + 1 < step.args.size()) {
      ++i;
      continue;
    }
    copy.args.push_back(step.args[i]);
  }
  return CommandLine(copy);
}

}  // namespace

DatasetFiles FilesOf(const ReportSettings& settings, const std::string& base) {
  DatasetFiles files;
  files.base = base;
  files.name = DisplayName(base);
  files.corrected_log = Join(settings.data_dir, base + "-corrected.log.gz");
  files.raw_log = Join(settings.data_dir, base + "-raw.log.gz");
  files.index = Join(settings.data_dir, base + "-raw-to-corrected.tsv");
  files.relations = Join(settings.data_dir, base + ".relations");
  return files;
}

std::string ReportArtefacts::Map(const ReportSettings& s, const std::string& base) {
  return Join(s.work_dir, "maps/" + base + ".kpm");
}
std::string ReportArtefacts::MapJson(const ReportSettings& s, const std::string& base) {
  return Join(s.work_dir, "maps/" + base + ".json");
}
std::string ReportArtefacts::MapPng(const ReportSettings& s, const std::string& base) {
  return Join(s.work_dir, "maps/" + base + ".png");
}
std::string ReportArtefacts::TableIIJson(const ReportSettings& s, const std::string& base) {
  return Join(s.work_dir, "maps/" + base + "-overlap-only.json");
}
std::string ReportArtefacts::RawMapJson(const ReportSettings& s, const std::string& base) {
  return Join(s.work_dir, "maps/" + base + "-raw-icp.json");
}
std::string ReportArtefacts::Localize(const ReportSettings& s, const std::string& base, bool raw,
                                      const std::string& preset, double lambda_m, int mu) {
  return Join(s.work_dir, fmt::format("localize/{}{}-{}-mu{}-lambda{}.json", base,
                                      raw ? "-raw" : "", preset, mu, LambdaText(lambda_m)));
}
std::string ReportArtefacts::TipFlirt(const ReportSettings& s, const std::string& base, int mu) {
  return Join(s.work_dir, "localize/" + base + "-tip-flirt" +
                              (mu == 10 ? "" : fmt::format("-mu{}", mu)) + ".json");
}
std::string ReportArtefacts::Relocalize(const ReportSettings& s, const std::string& base,
                                        bool raw) {
  return Join(s.work_dir, "relocalize/" + base + (raw ? "-raw" : "") + ".json");
}
std::string ReportArtefacts::RelocalizePng(const ReportSettings& s, const std::string& base,
                                           bool raw) {
  return Join(s.work_dir, "relocalize/" + base + (raw ? "-raw" : "") + ".png");
}
std::string ReportArtefacts::PreparationCache(const ReportSettings& s) {
  return Join(s.work_dir, "cache");
}
std::string ReportArtefacts::Fig8Dir(const ReportSettings& s, const std::string& base) {
  return Join(s.work_dir, "sweeps/fig8-" + base);
}
std::string ReportArtefacts::Fig9Dir(const ReportSettings& s, const std::string& base,
                                     const std::string& preset) {
  return Join(s.work_dir, "sweeps/fig9-" + base + "-" + preset);
}
std::string ReportArtefacts::SlamDir(const ReportSettings& s, const std::string& base) {
  return Join(s.work_dir, "slam/" + base + "-raw");
}

std::string ReportArtefacts::HospitalBag(const ReportSettings& s) {
  return Join(s.data_dir, "fr-clinic.orig.bag");
}
std::string ReportArtefacts::HospitalRelations(const ReportSettings& s) {
  return Join(s.data_dir, "fr-clinic.relations");
}
std::string ReportArtefacts::HospitalSlamDir(const ReportSettings& s) {
  return Join(s.work_dir, "slam/fr-clinic-bag");
}

std::vector<ReportStep> PlanReport(const ReportSettings& s) {
  using A = ReportArtefacts;
  std::vector<ReportStep> steps;
  const std::string n_pos = s.quick ? "20" : "500";
  const std::string starts = s.quick ? "6" : "50";
  const std::string threads = std::to_string(s.threads);
  const std::string cache = A::PreparationCache(s);
  const std::vector<std::string> presets{"default", "paper"};
  const std::vector<double> lambdas{0.05, 0.1};
  for (const std::string& base : s.datasets) {
    const DatasetFiles f = FilesOf(s, base);
    const std::string log = f.corrected_log;
    const std::string raw = f.raw_log;
    // Maps of the corrected log: default criteria (Figs 3-5, the localization map) and the
    // overlap criterion alone (Table II); the raw log with ICP poses (Table VI).
    steps.push_back({"map-" + base,
                     "Figure 3-5 map and localization map, " + f.name,
                     {"map", log, "--out", A::Map(s, base), "--json", A::MapJson(s, base), "--png",
                      A::MapPng(s, base), "--cache", cache},
                     {log},
                     {A::Map(s, base), A::MapJson(s, base), A::MapPng(s, base)}});
    steps.push_back(
        {"map-" + base + "-overlap-only",
         "Table II, " + f.name,
         {"map", log, "--overlap-only", "--json", A::TableIIJson(s, base), "--cache", cache},
         {log},
         {A::TableIIJson(s, base)}});
    steps.push_back(
        {"map-" + base + "-raw-icp",
         "Table VI, " + f.name + "_r",
         {"map", raw, "--poses", "icp", "--json", A::RawMapJson(s, base), "--cache", cache},
         {raw},
         {A::RawMapJson(s, base)}});
    // Global localization: Tables III/IV (corrected queries), VII/VIII (raw queries) and X
    // (mu 5 as well, FR079 and Intel only).
    for (const bool raw_queries : {false, true}) {
      std::vector<int> mus{10};
      if (raw_queries && base != "fr101") mus.push_back(5);
      for (const int mu : mus) {
        for (const std::string& preset : presets) {
          for (const double lambda : lambdas) {
            const std::string out = A::Localize(s, base, raw_queries, preset, lambda, mu);
            std::vector<std::string> args{"localize", "--map", A::Map(s, base)};
            std::vector<std::string> needs{A::Map(s, base)};
            if (raw_queries) {
              args.insert(args.end(),
                          {"--log", raw, "--poses", "icp", "--truth", log, "--index", f.index});
              needs.insert(needs.end(), {raw, log, f.index});
            } else {
              args.insert(args.end(), {"--log", log});
              needs.push_back(log);
            }
            args.insert(args.end(), {"--preset", preset, "--lambda", LambdaText(lambda), "--mu",
                                     std::to_string(mu), "--n-pos", n_pos, "--threads", threads,
                                     "--cache", cache, "--json", out});
            const std::string table =
                mu == 5 ? "Table X"
                        : (raw_queries ? (lambda < 0.07 ? "Table VII" : "Table VIII")
                                       : (lambda < 0.07 ? "Table III" : "Table IV"));
            steps.push_back({fmt::format("localize-{}{}-{}-mu{}-lambda{}", base,
                                         raw_queries ? "-raw" : "", preset, mu, LambdaText(lambda)),
                             fmt::format("{}, {}{}, {} preset, mu {}, lambda {} m", table, f.name,
                                         raw_queries ? "_r" : "", preset, mu, LambdaText(lambda)),
                             args,
                             needs,
                             {out}});
          }
        }
      }
    }
    if (base != "fr101") {
      steps.push_back({"localize-" + base + "-tip-flirt",
                       "Table X, TIP-FLIRT baseline, " + f.name,
                       {"localize", "--baseline", "tip-flirt", "--log", log, "--n-pos", n_pos,
                        "--threads", threads, "--cache", cache, "--json", A::TipFlirt(s, base)},
                       {log},
                       {A::TipFlirt(s, base)}});
      steps.push_back({"localize-" + base + "-tip-flirt-mu5",
                       "Table X, TIP-FLIRT baseline with mu 5 and consensus 5, " + f.name,
                       {"localize", "--baseline", "tip-flirt", "--log", log, "--mu", "5", "--set",
                        "place.min_consensus=5", "--n-pos", n_pos, "--threads", threads, "--cache",
                        cache, "--json", A::TipFlirt(s, base, 5)},
                       {log},
                       {A::TipFlirt(s, base, 5)}});
    }
    // The kidnapped robot (not in the paper): the corrected log against its own map with the
    // shared-scan exclusion, and the raw log with ICP odometry against the corrected map.
    for (const bool raw_queries : {false, true}) {
      const std::string json = A::Relocalize(s, base, raw_queries);
      const std::string png = A::RelocalizePng(s, base, raw_queries);
      std::vector<std::string> args{"relocalize", "--map", A::Map(s, base)};
      std::vector<std::string> needs{A::Map(s, base)};
      if (raw_queries) {
        args.insert(args.end(),
                    {"--log", raw, "--poses", "icp", "--truth", log, "--index", f.index});
        needs.insert(needs.end(), {raw, log, f.index});
      } else {
        args.insert(args.end(), {"--log", log, "--self-match", "shared-scan"});
        needs.push_back(log);
      }
      args.insert(args.end(), {"--starts", starts, "--threads", threads, "--cache", cache, "--json",
                               json, "--figure", png});
      steps.push_back(
          {"relocalize-" + base + (raw_queries ? "-raw" : ""),
           raw_queries
               ? "Kidnapped robot, " + f.name + "_r (ICP odometry) against the corrected map"
               : "Kidnapped robot, " + f.name + " against its own map (shared-scan exclusion)",
           args,
           needs,
           {json, png}});
    }
    // Figure 8: mapping criteria over s_min x l_g.
    const std::string fig8 = A::Fig8Dir(s, base);
    steps.push_back(
        {"sweep-mapping-" + base,
         "Figure 8, " + f.name,
         {"sweep", "mapping", "--log", log, "--s-min", s.quick ? "0.1,0.3,0.5" : "0:1:0.1", "--lg",
          s.quick ? "0.1,0.15" : "0.05,0.1,0.15", "--threads", threads, "--out", fig8},
         {log},
         {Join(fig8, "results.json")}});
    // Figure 9 (the paper: FR079 only, lambda 0.05) for both presets.
    if (base == "fr079") {
      for (const std::string& preset : presets) {
        const std::string fig9 = A::Fig9Dir(s, base, preset);
        steps.push_back(
            {fmt::format("sweep-place-{}-{}", base, preset),
             "Figure 9, " + f.name + ", " + preset + " preset",
             {"sweep", "place", "--map-log", log, "--mu", s.quick ? "5,10" : "5,10,15,20",
              "--gamma-min", s.quick ? "0,0.4,0.8" : "0:1:0.1", "--lambda", "0.05", "--preset",
              preset, "--n-pos", n_pos, "--threads", threads, "--out", fig9},
             {log},
             {Join(fig9, "results.json")}});
      }
    }
    // SLAM on the raw log: Table IX, loops, Figures 10-12.
    const std::string slam = A::SlamDir(s, base);
    std::vector<std::string> slam_args{"slam",         raw,
                                       "--out",        Join(slam, "map.kpm"),
                                       "--trajectory", Join(slam, "trajectory.tsv"),
                                       "--truth",      log,
                                       "--index",      f.index,
                                       "--json",       Join(slam, "slam.json"),
                                       "--loops",      Join(slam, "loops.tsv"),
                                       "--figures",    Join(slam, "figures")};
    if (Exists(f.relations)) slam_args.insert(slam_args.end(), {"--relations", f.relations});
    steps.push_back({"slam-" + base + "-raw",
                     "Table IX and Figures 10-12, " + f.name + "_r",
                     slam_args,
                     {raw, log, f.index},
                     {Join(slam, "slam.json"), Join(slam, "figures/trajectory.png")}});
  }
  // SLAM on the hospital bag (no corrected poses: relation error and trajectory only); a full
  // report only, as it takes minutes.
  if (!s.quick && Exists(A::HospitalBag(s)) && Exists(A::HospitalRelations(s))) {
    const std::string slam = A::HospitalSlamDir(s);
    steps.push_back({"slam-fr-clinic-bag",
                     "SLAM on the Freiburg hospital bag (issue 17's check set)",
                     {"slam", A::HospitalBag(s), "--relations", A::HospitalRelations(s), "--json",
                      Join(slam, "slam.json"), "--loops", Join(slam, "loops.tsv"), "--figures",
                      Join(slam, "figures")},
                     {A::HospitalBag(s), A::HospitalRelations(s)},
                     {Join(slam, "slam.json"), Join(slam, "figures/trajectory.png")}});
  }
  const std::vector<ReportStep> map_size = PlanMapSizeSteps(s);
  steps.insert(steps.end(), map_size.begin(), map_size.end());
  return steps;
}

std::string CommandLine(const ReportStep& step) {
  std::string line = "keyplace";
  for (const std::string& arg : step.args) line += " " + Quoted(arg);
  return line;
}

std::vector<StepOutcome> RunSteps(const ReportSettings& settings,
                                  const std::vector<ReportStep>& steps, const std::string& program,
                                  bool dry_run) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const std::string logs = Join(settings.work_dir, "logs");
  const std::string done = Join(settings.work_dir, "done");
  fs::create_directories(logs);
  fs::create_directories(done);
  std::vector<StepOutcome> outcomes(steps.size());
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const ReportStep& step = steps[k];
    StepOutcome& outcome = outcomes[k];
    const std::string command = CommandLine(step);
    const std::string identity = Identity(step);
    const std::string marker = Join(done, step.id + ".cmd");
    const std::string header =
        fmt::format("[{}/{}] {} ({})", k + 1, steps.size(), step.id, step.what);
    bool outputs_exist = true;
    for (const std::string& output : step.outputs) outputs_exist = outputs_exist && Exists(output);
    if (outputs_exist && Exists(marker) && ReadText(marker) == identity + "\n") {
      outcome.state = StepState::kDone;
      fmt::print("{}: done before\n", header);
      continue;
    }
    std::string missing;
    for (const std::string& need : step.needs) {
      if (!Exists(need)) {
        missing = need;
        break;
      }
    }
    if (!missing.empty()) {
      outcome.state = StepState::kSkipped;
      outcome.message = "needs " + missing + ", which does not exist";
      fmt::print("{}: skipped, {}\n", header, outcome.message);
      continue;
    }
    if (dry_run) {
      outcome.state = StepState::kSkipped;
      outcome.message = "not run (--no-run)";
      fmt::print("{}: not run (--no-run)\n", header);
      continue;
    }
    fmt::print("{}\n    {}\n", header, command);
    std::fflush(stdout);
    for (const std::string& output : step.outputs) {
      fs::create_directories(fs::path(output).parent_path());
    }
    std::error_code ignored;
    fs::remove(marker, ignored);
    const std::string log_path = Join(logs, step.id + ".log");
    const auto step_start = Clock::now();
    std::string error;
    const int status = Spawn(program, step.args, log_path, error);
    outcome.seconds = std::chrono::duration<double>(Clock::now() - step_start).count();
    const double total = std::chrono::duration<double>(Clock::now() - start).count();
    if (status != 0) {
      outcome.state = StepState::kFailed;
      outcome.message = fmt::format("{} (exit status {}); its output is in {}",
                                    error.empty() ? "failed" : error, status, log_path);
    } else {
      for (const std::string& output : step.outputs) {
        if (!Exists(output)) {
          outcome.state = StepState::kFailed;
          outcome.message = fmt::format("finished but did not write {}; see {}", output, log_path);
          break;
        }
      }
      if (outcome.message.empty()) {
        outcome.state = StepState::kRan;
        WriteFileAtomically(marker, [&](std::ostream& out) { out << identity << "\n"; });
      }
    }
    if (outcome.state == StepState::kFailed) {
      fmt::print("    FAILED after {}: {}\n", Elapsed(outcome.seconds), outcome.message);
    } else {
      fmt::print("    done in {} (report running for {})\n", Elapsed(outcome.seconds),
                 Elapsed(total));
    }
    std::fflush(stdout);
  }
  return outcomes;
}

std::string StepStateName(StepState state) {
  switch (state) {
    case StepState::kDone:
      return "done";
    case StepState::kRan:
      return "ran";
    case StepState::kFailed:
      return "failed";
    case StepState::kSkipped:
      return "skipped";
  }
  return "";
}

}  // namespace keyplace::cli
