// "Did you mean …": the closest known word to a misspelt one.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tickfx::io {

/// Optimal-string-alignment distance (Levenshtein plus adjacent transpositions), ignoring ASCII
/// case: "integratr" → "integrator" is 1, "rk5" → "rk4" is 1, "RK4" → "rk4" is 0.
std::size_t editDistance(std::string_view a, std::string_view b);

/// The candidate closest to `word`, when it is close enough to be the likely intent: at most
/// max(1, (|word| + 1) / 3) edits away and fewer edits than the word has letters. Ties go to
/// the earlier candidate.
std::optional<std::string> closestMatch(std::string_view word,
                                        const std::vector<std::string>& candidates);

}  // namespace tickfx::io
