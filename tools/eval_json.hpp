#pragma once
// JSON (and short text) forms of evaluation results shared by several subcommands.

#include <string>

#include <nlohmann/json.hpp>

#include "keyplace/eval/relation_error.hpp"

namespace keyplace::cli {

/// count, mean / std / max of the translational (m) and rotational (deg) errors.
nlohmann::json StatsJson(const ErrorStats& stats);

/// The Kümmerle relation error: flat keys for scripts (translation_mean_m, local_*, loop_*) and
/// the full statistics of each split under "all", "local" and "loop"; all of them null, and
/// "refusal" saying why, when too few relations matched.
nlohmann::json RelationJson(const RelationErrorReport& report);

/// ", N outside the log's time span" when relations were left out for that, else "".
std::string OutsideSpanNote(const RelationErrorReport& report);

}  // namespace keyplace::cli
