// libFuzzer harness of the relation file reader (ReadRelations, Kümmerle et al.'s
// `t_a t_b dx dy dz droll dpitch dyaw` lines). Correct rejection is std::invalid_argument naming
// the file; anything else, and a relation the reader's contract excludes, is a finding.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz_input_file.hpp"
#include "keyplace/io/relations.hpp"

namespace {

// Every number finite (the reader refuses others), the angle wrapped, lines in file order.
void CheckRelations(const std::vector<keyplace::Relation>& relations) {
  std::size_t previous_line = 0;
  for (const keyplace::Relation& relation : relations) {
    const keyplace::Pose2& pose = relation.T_a_b;
    if (!std::isfinite(relation.timestamp_a_s) || !std::isfinite(relation.timestamp_b_s) ||
        !std::isfinite(pose.x) || !std::isfinite(pose.y)) {
      keyplace::fuzz::Finding("relation of line " + std::to_string(relation.line) +
                              ": a number is not finite");
    }
    if (!(pose.theta > -M_PI && pose.theta <= M_PI)) {
      keyplace::fuzz::Finding("relation of line " + std::to_string(relation.line) +
                              ": angle not wrapped to (-pi, pi]");
    }
    if (relation.line <= previous_line) keyplace::fuzz::Finding("relation lines out of order");
    previous_line = relation.line;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("relations");
  const std::string& path = file.Write(data, size);
  try {
    CheckRelations(keyplace::ReadRelations(path));
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), path);
  }
  return 0;
}
