// libFuzzer harness of the CARMEN log reader (ReadCarmenLog): plain and gzip text, every message
// type. Correct rejection is std::invalid_argument (malformed line) or std::runtime_error
// (compressed data cut off) naming the file; anything else, and a log that breaks the reader's
// documented guarantees, is a finding.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "log_checks.hpp"

namespace {

// Reads the file; true when it was rejected with a documented error.
bool Read(const std::string& path, const keyplace::CarmenReadOptions& options) {
  try {
    keyplace::fuzz::CheckLog(keyplace::ReadCarmenLog(path, options));
    return false;
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), path);
  } catch (const std::runtime_error& error) {
    keyplace::fuzz::ExpectNamedError("std::runtime_error", error.what(), path);
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("carmen-log");
  const std::string& path = file.Write(data, size);
  if (Read(path, {})) {
    // The same input again, skipping malformed lines: the other path through the reader.
    keyplace::CarmenReadOptions skipping;
    skipping.skip_bad_lines = true;
    Read(path, skipping);
  }
  return 0;
}
