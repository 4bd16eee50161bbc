#pragma once
// Decoded frames as NumPy arrays.
#include <pybind11/numpy.h>

#include "video/movie_reader.hpp"

namespace panoptes::python {

/// The frame as a new uint8 array of shape (height, width, 3), RGB, converted from YUV 4:2:0 exactly
/// as the player's headless frames and `panoptes export-path` do (video::MovieReader::to_rgba).
pybind11::array_t<std::uint8_t> rgb_array(const video::YuvFrame& frame);

}  // namespace panoptes::python
