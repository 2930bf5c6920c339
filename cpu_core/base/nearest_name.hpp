// Suggestions for a misspelt name: "did you mean fov_y?" after an unknown key, option or
// keyword, so that a typo is answered with its fix.
#pragma once
#include <string>
#include <vector>

namespace abcube {

// The known name closest to `given` by edit distance (insertions, deletions,
// substitutions and swaps of neighbours, letter case ignored), when it is close enough
// to be the name meant: at most a third of the longer name's letters apart, and 2 at
// most. "" when none is.
std::string nearest_name(const std::string& given, const std::vector<std::string>& known);

// "; did you mean NAME?" for the nearest name, or "".
std::string did_you_mean(const std::string& given, const std::vector<std::string>& known);

}  // namespace abcube
