#include "core/config/key_suggestion.h"

#include <algorithm>
#include <cctype>

namespace lantern {

namespace {

char lower(char c) {
  return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
}

std::string join_keys(const std::vector<std::string> &keys) {
  std::string out;
  for (const std::string &k : keys) out += (out.empty() ? "" : ", ") + k;
  return out;
}

}  // namespace

size_t edit_distance(const std::string &a, const std::string &b) {
  // Two-row dynamic programme: row[j] = distance between a[0..i) and b[0..j).
  std::vector<size_t> previous(b.size() + 1);
  std::vector<size_t> current(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t substitute = previous[j - 1] + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitute});
    }
    std::swap(previous, current);
  }
  return previous[b.size()];
}

std::string nearest_key(const std::string &key, const std::vector<std::string> &candidates) {
  std::string best;
  size_t best_distance = 0;
  for (const std::string &candidate : candidates) {
    const size_t d = edit_distance(key, candidate);
    if (best.empty() || d < best_distance) {
      best = candidate;
      best_distance = d;
    }
  }
  return best;
}

std::string suggestion_text(const std::string &key, const std::vector<std::string> &candidates) {
  if (candidates.empty()) return "";
  return "did you mean '" + nearest_key(key, candidates) +
         "'? (valid keys: " + join_keys(candidates) + ")";
}

}  // namespace lantern
