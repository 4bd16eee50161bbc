#include "python/frame_array.hpp"

#include <cstring>

namespace py = pybind11;

namespace panoptes::python {

py::array_t<std::uint8_t> rgb_array(const video::YuvFrame& frame) {
  Image rgba;
  {
    py::gil_scoped_release release;
    rgba = video::MovieReader::to_rgba(frame);
  }
  py::array_t<std::uint8_t> out({py::ssize_t(rgba.height), py::ssize_t(rgba.width), py::ssize_t(3)});
  std::uint8_t* dst = out.mutable_data();
  const std::uint8_t* src = rgba.pixels.data();
  const std::size_t n = std::size_t(rgba.width) * std::size_t(rgba.height);
  for (std::size_t i = 0; i < n; ++i, dst += 3, src += 4) std::memcpy(dst, src, 3);
  return out;
}

}  // namespace panoptes::python
