#pragma once
// Internal: text taken from an input (a field, a key, a frame id, a topic) as an error message
// shows it: bounded, so that a 1 MB frame id costs no more than a short one, and with control
// bytes escaped, so that a NUL byte does not cut the message where C strings end.

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace keyplace {

/// At most `max_bytes` bytes of `text`, then "... (N bytes)"; bytes below 0x20 and 0x7f as \0,
/// \t, \n, \r or \xNN, and a backslash as \\ so that the escapes are unambiguous.
inline std::string ShownText(std::string_view text, std::size_t max_bytes = 80) {
  std::string shown;
  const std::size_t kept = text.size() > max_bytes ? max_bytes : text.size();
  for (std::size_t i = 0; i < kept; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte == 0) {
      shown += "\\0";
    } else if (byte == '\t') {
      shown += "\\t";
    } else if (byte == '\n') {
      shown += "\\n";
    } else if (byte == '\r') {
      shown += "\\r";
    } else if (byte == '\\') {
      shown += "\\\\";
    } else if (byte < 0x20 || byte == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", byte);
      shown += escaped;
    } else {
      shown += static_cast<char>(byte);
    }
  }
  if (kept < text.size()) shown += "... (" + std::to_string(text.size()) + " bytes)";
  return shown;
}

}  // namespace keyplace
