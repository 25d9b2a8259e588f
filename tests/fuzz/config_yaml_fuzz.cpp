// libFuzzer harness of the configuration file reader (ApplyConfigYaml, the text behind
// --config FILE.yaml), through its in-memory entry point. Correct rejection is
// std::invalid_argument naming the source; anything else is a finding, and so is an accepted
// file that leaves an invalid configuration or one that does not survive ConfigToYaml and back.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/config/config.hpp"

namespace {

constexpr const char* kSource = "fuzz-config.yaml";

void CheckAccepted(const keyplace::Config& config) {
  try {
    keyplace::Validate(config);
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::Finding(std::string("accepted, yet invalid: ") + error.what());
  }
  // "Loading it gives back the same configuration" (config.hpp, ConfigToYaml).
  keyplace::Config reloaded;
  try {
    keyplace::ApplyConfigYaml(keyplace::ConfigToYaml(config), "round trip", reloaded);
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::Finding(std::string("ConfigToYaml of an accepted file does not load: ") +
                            error.what());
  }
  if (keyplace::ConfigKeyValues(reloaded) != keyplace::ConfigKeyValues(config)) {
    keyplace::fuzz::Finding("ConfigToYaml of an accepted file loads as another configuration");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string yaml(reinterpret_cast<const char*>(data), size);
  keyplace::Config config;
  try {
    keyplace::ApplyConfigYaml(yaml, kSource, config);
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), kSource);
    return 0;
  }
  CheckAccepted(config);
  return 0;
}
