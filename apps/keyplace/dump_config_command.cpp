// keyplace dump-config: the whole effective configuration as YAML, every field with its unit and
// meaning; the output is a valid --config file.

#include <iostream>
#include <memory>

#include "commands.hpp"
#include "config_options.hpp"

namespace keyplace::cli {

void RegisterDumpConfigCommand(CLI::App& app) {
  auto options = std::make_shared<ConfigOptions>();
  CLI::App* command = app.add_subcommand(
      "dump-config",
      "Print the effective configuration (preset, --config file and --set applied) as YAML: every "
      "section and field with its unit and meaning. The output is a valid --config file.");
  AddConfigOptions(command, *options);
  command->callback([options] { std::cout << ConfigToYaml(ResolveConfig(*options)); });
}

}  // namespace keyplace::cli
