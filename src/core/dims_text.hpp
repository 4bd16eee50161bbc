#pragma once
// "920x896", "4x4x3": counts joined by 'x', as the command line takes image sizes and lattices.
#include <optional>
#include <string_view>
#include <vector>

namespace panoptes {

/// The `parts` counts of text like "920x896" (parts = 2) or "4x4x3" (parts = 3): each 1..max_digits
/// decimal digits, nothing else; nullopt when the text is not of that form.
std::optional<std::vector<int>> parse_dims_text(std::string_view text, int parts, int max_digits);

}  // namespace panoptes
