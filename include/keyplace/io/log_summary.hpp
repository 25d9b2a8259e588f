#pragma once
// Figures of a whole log that describe it (keyplace info, the Python module): its path length and
// how its FLASER beams were spread.

#include <cstddef>
#include <string>

#include "keyplace/io/carmen_log.hpp"

namespace keyplace {

/// Length (m) of the path through the scans' poses (corrected when the log has them, else
/// odometry); scans without a pose are skipped.
double LogPathLengthM(const CarmenLog& log);

/// How the log's FLASER lines had their beams spread: ToString(FlaserSpacing) when all lines used
/// one rule, "mixed" when both occur, "" without FLASER lines (other lines state their angles).
std::string FlaserSpacingRule(const CarmenLog& log);

/// In words, for people: how `over_n` FLASER scans spread as fov/n and `over_n_minus_one` as
/// fov/(n-1) had their beams spread (both counts when both occur).
std::string FlaserSpacingText(std::size_t over_n, std::size_t over_n_minus_one);

}  // namespace keyplace
