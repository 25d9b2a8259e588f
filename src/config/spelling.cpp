#include "config/spelling.hpp"

#include <algorithm>
#include <utility>

namespace keyplace {
namespace {

std::string LastPart(const std::string& name) { return name.substr(name.rfind('.') + 1); }

}  // namespace

std::size_t EditDistance(const std::string& a, const std::string& b) {
  // Optimal string alignment over three rows (a's first i - 2, i - 1 and i characters against
  // b's first j): memory grows with b only, so a long a costs time, not a table.
  std::vector<std::size_t> two_back(b.size() + 1);
  std::vector<std::size_t> previous(b.size() + 1);
  std::vector<std::size_t> current(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        current[j] = std::min(current[j], two_back[j - 2] + 1);
      }
    }
    std::swap(two_back, previous);
    std::swap(previous, current);
  }
  return previous[b.size()];
}

std::vector<std::string> ClosestNames(const std::string& word,
                                      const std::vector<std::string>& candidates) {
  const std::size_t limit = std::max<std::size_t>(1, LastPart(word).size() / 4);
  std::vector<std::pair<std::size_t, std::string>> close;
  for (const std::string& candidate : candidates) {
    const bool same_last_part = LastPart(candidate) == LastPart(word) && candidate != word;
    // The distance is at least the difference in length: a long word (a hostile key of a
    // megabyte) is not compared cell by cell with every name.
    const std::size_t length_difference = word.size() > candidate.size()
                                              ? word.size() - candidate.size()
                                              : candidate.size() - word.size();
    if (length_difference > limit && !same_last_part) continue;
    const std::size_t distance = EditDistance(word, candidate);
    if (distance <= limit || same_last_part) close.emplace_back(distance, candidate);
  }
  std::stable_sort(close.begin(), close.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> names;
  for (const auto& entry : close) {
    if (names.size() == 3) break;
    if (std::find(names.begin(), names.end(), entry.second) == names.end()) {
      names.push_back(entry.second);
    }
  }
  return names;
}

std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::vector<std::string> names = ClosestNames(word, candidates);
  if (names.empty()) return "";
  std::string text = "; did you mean ";
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) text += i + 1 == names.size() ? " or " : ", ";
    text += "'" + names[i] + "'";
  }
  return text + "?";
}

}  // namespace keyplace
