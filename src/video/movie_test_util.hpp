#pragma once
// Synthetic "rendered-looking" frames for the video tests and benchmark: smooth gradients and shaded
// shapes that move with the frame number (like a rendered simulation), plus a frame stamp so a test
// can tell which frame a decoder returned.
#include "core/image.hpp"

namespace panoptes::video::testing {

/// Frame `index` of a w x h test movie (3 or 4 channels), stamped with FrameStamp{0, 0, index} when
/// the image is large enough for a stamp (40 x 32 or more).
Image make_test_frame(int width, int height, int index, int channels = 3);

/// The frame number stamped into image, or -1 if there is no valid stamp.
int read_test_frame_number(const Image& image);

}  // namespace panoptes::video::testing
