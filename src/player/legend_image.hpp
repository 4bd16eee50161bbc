#pragma once
// A task's colour legend drawn into a frame (issue 41): what the window's HUD and the web player show
// beside the picture, burnt into pictures that leave Panoptes (export-path previews, Cinema exports
// with --legend), so a movie shown in a talk still says what its colours stand for.
#include "core/image.hpp"
#include "store/manifest.hpp"

namespace panoptes::player {

/// Draws the legend of `task` at `frame` (player::task_legend: each bar's label and unit, its colours,
/// its window's ends, the scale line with the factor when the reference just changed) on a translucent
/// dark panel in the bottom-left corner of `image` (8-bit RGB or RGBA). Text is stb_easy_font's bitmap
/// font, twice as large on images 600 or more pixels high. Tasks without a legend leave the image as it
/// is. Returns the panel's height in pixels (0 = nothing drawn).
int draw_legend(Image& image, const store::Manifest& manifest, int task, int frame);

}  // namespace panoptes::player
