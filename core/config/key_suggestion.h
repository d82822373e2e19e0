// Nearest-key suggestions for configuration errors ("did you mean 'azimuth'?").
//
// Pure functions, no state: safe to call from any thread.
#pragma once

#include <string>
#include <vector>

namespace lantern {

// Levenshtein edit distance (insertions, deletions, substitutions, each cost 1), compared
// case-insensitively so `Width` is one step from nothing rather than a different word.
size_t edit_distance(const std::string &a, const std::string &b);

// The candidate with the smallest edit distance to `key` (the first one on ties); "" if
// `candidates` is empty.
std::string nearest_key(const std::string &key, const std::vector<std::string> &candidates);

// "did you mean 'azimuth'?" for the nearest candidate, followed by the list of valid keys so that
// a far-off guess still shows the user what is allowed. "" if `candidates` is empty.
std::string suggestion_text(const std::string &key, const std::vector<std::string> &candidates);

}  // namespace lantern
