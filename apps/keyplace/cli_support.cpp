#include "cli_support.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <stdexcept>

#include <fmt/core.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "io/atomic_file.hpp"
#include "keyplace/mapping/map_server.hpp"

namespace keyplace::cli {

std::size_t WorkerThreads(int threads) {
  if (threads < 0) {
    throw std::invalid_argument("--threads " + std::to_string(threads) +
                                ": expected 0 (all cores) or more");
  }
  return threads > 0 ? static_cast<std::size_t>(threads)
                     : static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
}

void RunOnWorkerThreads(int threads, const std::function<void()>& work) {
  const std::size_t count = WorkerThreads(threads);
  // Each alone caps the threads at the cores: the global control lifts TBB's worker limit, the
  // arena makes this work use that many.
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism, count);
  tbb::task_arena arena(static_cast<int>(count));
  arena.execute(work);
}

namespace {

// Every value given to `command`'s options and positionals but those of `outputs`.
std::vector<std::string> GivenInputs(
    const CLI::App& command, const std::vector<std::pair<std::string, std::string>>& outputs) {
  std::vector<std::string> inputs;
  for (const CLI::Option* option : command.get_options()) {
    const bool is_output = std::any_of(outputs.begin(), outputs.end(), [&](const auto& output) {
      return output.first.rfind("--", 0) == 0 && option->check_name(output.first);
    });
    if (is_output || option->get_type_size_max() == 0) continue;  // an output, or a flag
    for (const std::string& value : option->results()) inputs.push_back(value);
  }
  return inputs;
}

}  // namespace

void CheckOutputs(const CLI::App& command,
                  const std::vector<std::pair<std::string, std::string>>& outputs,
                  const std::vector<std::string>& more_inputs) {
  std::vector<std::string> inputs = GivenInputs(command, outputs);
  inputs.insert(inputs.end(), more_inputs.begin(), more_inputs.end());
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const auto& [option, path] = outputs[i];
    if (path.empty()) continue;
    try {
      CheckOutputPath(path, inputs);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(option + " " + error.what());
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (outputs[j].second == path) {
        std::string message = option;
        message += " " + path;
        message += ": also given to " + outputs[j].first;
        throw std::invalid_argument(message);
      }
    }
  }
}

void CheckNotReserved(const std::string& option, const std::string& path,
                      const std::vector<std::string>& reserved, const std::string& owner) {
  if (path.empty()) return;
  namespace fs = std::filesystem;
  const auto normal = [](const std::string& name) {
    std::error_code error;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(name), error);
    return error ? fs::absolute(name).lexically_normal() : canonical;
  };
  const fs::path target = normal(path);
  for (const std::string& own : reserved) {
    if (target == normal(own)) {
      std::string message = option;
      message += " " + path;
      message += ": is " + owner;
      message += " " + own;
      message += "; writing the JSON there would replace it";
      throw std::invalid_argument(message);
    }
  }
}

ScanRange ParseScanRange(const std::string& text, std::size_t count) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    throw std::invalid_argument("--scans '" + text + "': expected A:B (e.g. 0:50, :100, 200:)");
  }
  const auto parse = [&](const std::string& part, std::size_t fallback) -> std::size_t {
    if (part.empty()) return fallback;
    std::size_t used = 0;
    long long value = -1;
    try {
      value = std::stoll(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != part.size() || value < 0) {
      throw std::invalid_argument("--scans '" + text + "': '" + part +
                                  "' is not a non-negative integer");
    }
    return static_cast<std::size_t>(value);
  };
  ScanRange range;
  range.begin = std::min(parse(text.substr(0, colon), 0), count);
  range.end = std::min(parse(text.substr(colon + 1), count), count);
  if (range.end < range.begin) {
    throw std::invalid_argument("--scans '" + text + "': end is before begin");
  }
  return range;
}

void ApplyScanRange(const std::string& text, LogInputOptions& options) {
  if (text.empty()) return;
  const ScanRange range = ParseScanRange(text, std::numeric_limits<std::size_t>::max());
  options.first_scan = range.begin;
  options.end_scan = range.end;
}

std::vector<std::pair<std::string, std::string>> GridOutputs(const std::string& yaml_path) {
  if (yaml_path.empty()) return {};
  const std::string extension = std::filesystem::path(yaml_path).extension().string();
  if (extension != ".yaml" && extension != ".yml") {
    throw std::invalid_argument("--grid " + yaml_path +
                                ": expected a .yaml file (its image goes beside it as .pgm)");
  }
  return {{"--grid", yaml_path}, {"--grid (its image)", MapServerImagePath(yaml_path)}};
}

}  // namespace keyplace::cli
