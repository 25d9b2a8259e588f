// keyplace dump-config: the effective configuration as YAML, each field with its unit and meaning:
// the essential settings and those changed from the defaults, or with --all every field; the
// output is a valid --config file either way.

#include <iostream>
#include <memory>
#include <string>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/config/essential_settings.hpp"

namespace keyplace::cli {

void RegisterDumpConfigCommand(CLI::App& app) {
  auto options = std::make_shared<ConfigOptions>();
  auto json_path = std::make_shared<std::string>();
  auto all = std::make_shared<bool>(false);
  CLI::App* command = app.add_subcommand(
      "dump-config",
      "Print the effective configuration (preset, --config file and --set applied) as YAML, each "
      "field with its unit and meaning: the essential settings (sensor range, bag topics and "
      "frames, submap size, how sure a fix must be, the robot node's outputs) and every setting "
      "that differs from the defaults; --all prints every field. The output is a valid --config "
      "file.");
  AddConfigOptions(command, *options);
  command->add_flag("--all", *all, "Print every field, not only the essential and changed ones");
  command->add_option("--json", *json_path,
                      "Also write the configuration as JSON to FILE (the \"config\" object the "
                      "other commands' --json carries)");
  command->callback([command, options, json_path, all] {
    CheckOutputs(*command, {{"--json", *json_path}});
    const Config config = ResolveConfig(*options);
    std::cout << (*all ? ConfigToYaml(config) : EssentialConfigToYaml(config));
    if (!json_path->empty()) WriteJson(*json_path, ConfigJson(config));
  });
}

}  // namespace keyplace::cli
