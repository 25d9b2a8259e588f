#pragma once
// Each subcommand of the keyplace tool lives in its own <name>_command.cpp and registers itself
// on the CLI11 app with one of these functions (called from main.cpp).

#include <CLI/CLI.hpp>

namespace keyplace::cli {

void RegisterInfoCommand(CLI::App& app);
void RegisterFeaturesCommand(CLI::App& app);
void RegisterOdometryCommand(CLI::App& app);
void RegisterMapCommand(CLI::App& app);
void RegisterLocalizeCommand(CLI::App& app);
void RegisterRelocalizeCommand(CLI::App& app);
void RegisterSlamCommand(CLI::App& app);
void RegisterMergeCommand(CLI::App& app);
void RegisterSweepCommand(CLI::App& app);
void RegisterReportCommand(CLI::App& app);
void RegisterDumpConfigCommand(CLI::App& app);

}  // namespace keyplace::cli
