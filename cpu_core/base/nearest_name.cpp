#include "base/nearest_name.hpp"

#include <algorithm>
#include <cctype>

namespace abcube {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Optimal string alignment distance: Levenshtein with transpositions of neighbours.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

}  // namespace

std::string nearest_name(const std::string& given, const std::vector<std::string>& known) {
  // Names in messages are short; a long input is no typo of one.
  if (given.empty() || given.size() > 64) return "";
  const std::string g = lower(given);
  std::string best;
  size_t best_distance = 3;  // more than the largest distance accepted
  for (const std::string& k : known) {
    const size_t limit = std::min<size_t>(2, std::max(g.size(), k.size()) / 3);
    const size_t d = edit_distance(g, lower(k));
    if (d <= limit && d < best_distance && given != k) {
      best = k;
      best_distance = d;
    }
  }
  return best;
}

std::string did_you_mean(const std::string& given, const std::vector<std::string>& known) {
  const std::string n = nearest_name(given, known);
  return n.empty() ? "" : "; did you mean " + n + "?";
}

}  // namespace abcube
