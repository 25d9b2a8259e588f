// keyplace: place recognition with stable 2D-LiDAR keypoints (command-line front end).

#include <exception>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "keyplace: compact maps of stable FLIRT keypoints from 2D laser logs, and place recognition "
      "(global localization, loop closure) against them.\n"
      "Logs are CARMEN text files, plain or .gz."};
  app.set_version_flag("--version", "keyplace 0.1.0");
  app.require_subcommand(1);
  keyplace::cli::RegisterInfoCommand(app);
  keyplace::cli::RegisterFeaturesCommand(app);
  keyplace::cli::RegisterOdometryCommand(app);
  keyplace::cli::RegisterMapCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  } catch (const std::exception& error) {
    fmt::print(stderr, "keyplace: error: {}\n", error.what());
    return 1;
  }
  return 0;
}
