// keyplace dump-config: the whole effective configuration as YAML, every field with its unit and
// meaning; the output is a valid --config file.

#include <iostream>
#include <memory>
#include <string>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"

namespace keyplace::cli {

void RegisterDumpConfigCommand(CLI::App& app) {
  auto options = std::make_shared<ConfigOptions>();
  auto json_path = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "dump-config",
      "Print the effective configuration (preset, --config file and --set applied) as YAML: every "
      "section and field with its unit and meaning. The output is a valid --config file.");
  AddConfigOptions(command, *options);
  command->add_option("--json", *json_path,
                      "Also write the configuration as JSON to FILE (the \"config\" object the "
                      "other commands' --json carries)");
  command->callback([command, options, json_path] {
    CheckOutputs(*command, {{"--json", *json_path}});
    const Config config = ResolveConfig(*options);
    std::cout << ConfigToYaml(config);
    if (!json_path->empty()) WriteJson(*json_path, ConfigJson(config));
  });
}

}  // namespace keyplace::cli
