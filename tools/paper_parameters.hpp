#pragma once
// The paper's parameters: Table V (l_g, s_min, mu, gamma_min, lambda) and the values its text
// gives for the others (Sections 3-5), to print beside our defaults.

#include <vector>

namespace keyplace::cli {

struct PaperParameter {
  const char* name;     // as in the paper: "l_g (m)"
  const char* source;   // "Table V" or the section of the text
  double value;         // the paper's value
  const char* meaning;  // one line
};

/// In the paper's order: Table V first, then the text's.
const std::vector<PaperParameter>& PaperParameters();

}  // namespace keyplace::cli
