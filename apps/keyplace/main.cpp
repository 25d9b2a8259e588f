// keyplace: place recognition with stable 2D-LiDAR keypoints (command-line front end).

#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "config/spelling.hpp"

namespace {

// A first word that is no option and no command: CLI11 would say a subcommand is required.
bool UnknownCommand(const CLI::App& app, const std::string& word) {
  if (word.empty() || word.front() == '-') return false;
  std::vector<std::string> commands;
  for (const CLI::App* command : app.get_subcommands({})) {
    if (command->get_name() == word) return false;
    commands.push_back(command->get_name());
  }
  std::fprintf(stderr,
               "keyplace: error: '%s' is not a keyplace command%s (keyplace --help lists them)\n",
               word.c_str(), keyplace::DidYouMean(word, commands).c_str());
  return true;
}

int Run(int argc, char** argv) {
  CLI::App app{
      "keyplace: compact maps of stable FLIRT keypoints from 2D laser logs, and place recognition "
      "(global localization, loop closure) against them.\n"
      "Logs are CARMEN text files, plain or .gz, ROS 1 bags or ROS 2 bags (rosbag2 directory, "
      ".mcap or .db3; --scan-topic, --odom-topic, "
      "--laser-pose; docs/ROS.md)."};
  app.set_version_flag("--version", std::string("keyplace ") + KEYPLACE_VERSION);
  app.require_subcommand(1);
  keyplace::cli::RegisterInfoCommand(app);
  keyplace::cli::RegisterFeaturesCommand(app);
  keyplace::cli::RegisterOdometryCommand(app);
  keyplace::cli::RegisterMapCommand(app);
  keyplace::cli::RegisterLocalizeCommand(app);
  keyplace::cli::RegisterRelocalizeCommand(app);
  keyplace::cli::RegisterSlamCommand(app);
  keyplace::cli::RegisterMergeCommand(app);
  keyplace::cli::RegisterSweepCommand(app);
  keyplace::cli::RegisterReportCommand(app);
  keyplace::cli::RegisterDumpConfigCommand(app);
  if (argc > 1 && UnknownCommand(app, argv[1])) return 1;
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& error) {
    return error.get_exit_code();  // a command that printed its own failure (report)
  } catch (const CLI::ParseError& error) {
    // --help and --version end here with status 0. A usage error (a missing path, an unknown
    // option) is an error like any other: the same prefix and exit status 1, not CLI11's codes
    // (105 for a missing file).
    if (error.get_exit_code() == 0) return app.exit(error);
    std::fprintf(stderr, "keyplace: error: %s\nRun with --help for more information.\n",
                 error.what());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::bad_alloc&) {
    // Readers and loaders name their file when memory runs out; this is what is left.
    std::fprintf(stderr,
                 "keyplace: error: out of memory (the input is too large for this machine's "
                 "memory)\n");
  } catch (const std::exception& error) {
    std::fprintf(stderr, "keyplace: error: %s\n", error.what());
  } catch (...) {
    std::fprintf(stderr, "keyplace: error: unknown exception\n");
  }
  return 1;
}
