#pragma once
// "Did you mean": the names closest to a mistyped one (configuration keys, subcommands).

#include <string>
#include <vector>

namespace keyplace {

/// Edit distance: insertions, deletions, substitutions and swaps of two neighbouring characters
/// ("mpa" -> "map"), one edit each.
std::size_t EditDistance(const std::string& a, const std::string& b);

/// The names of `candidates` within a few edits of `word` (one per four characters of its last
/// dot-separated part, at least one: a short name is not matched to every other short name),
/// closest first, and those whose last part is the same as `word`'s (the right key in another
/// section); at most three.
std::vector<std::string> ClosestNames(const std::string& word,
                                      const std::vector<std::string>& candidates);

/// "; did you mean 'a' or 'b'?" for ClosestNames, or "" when none is close.
std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace keyplace
