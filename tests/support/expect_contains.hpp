#pragma once
// An expectation that an error message (or any text) contains a fragment, printing both.

#include <string>

#include <gtest/gtest.h>

namespace keyplace::testing {

inline void ExpectContains(const std::string& text, const std::string& fragment) {
  EXPECT_NE(text.find(fragment), std::string::npos)
      << "'" << text << "' lacks '" << fragment << "'";
}

}  // namespace keyplace::testing
