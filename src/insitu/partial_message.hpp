#pragma once
// Partial images as MPI messages (the session's compositing: direct send and bands). A message is the
// rows' rect and whether it carries sliver state (5 int32), then per pixel premultiplied RGBA and depth
// (5 floats); an anti-aliased isosurface of a brick that is not the whole domain adds its colour if a
// sliver is open at its front (4 floats) and its end state (1 byte, render::SliverEnd): 9 floats and a
// byte per pixel instead of 5, for those tasks only.
#include <vector>

#include "render/partial_image.hpp"

namespace panoptes::insitu {

/// Appends rows [y0, y1) of `p` (inside its rect) to `out` as one message.
void pack_rows(const render::PartialImage& p, int y0, int y1, std::vector<char>& out);
/// Appends the whole of `p` (its rect) to `out` as one message.
void pack(const render::PartialImage& p, std::vector<char>& out);
/// Reads one message from [in, end) into `p` (a width × height image); returns the byte after it.
/// Throws panoptes::Error when the message is cut short.
const char* unpack(const char* in, const char* end, int width, int height, render::PartialImage& p);

}  // namespace panoptes::insitu
