#include "cinema/image_file.hpp"

#include <unistd.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>

#include <jpeglib.h>
#include <png.h>

#include "core/error.hpp"
#include "store/manifest.hpp"
#include "store/safe_file.hpp"

namespace panoptes::cinema {
namespace fs = std::filesystem;

namespace {

bool is_png(const std::uint8_t* d, std::size_t n) { return n >= 8 && std::memcmp(d, "\x89PNG\r\n\x1a\n", 8) == 0; }
bool is_jpeg(const std::uint8_t* d, std::size_t n) { return n >= 3 && d[0] == 0xFF && d[1] == 0xD8 && d[2] == 0xFF; }

std::string read_bytes(const fs::path& path, std::uint64_t limit) {
  const auto [dir, name] = store::split_parent(path);
  const store::FileHandle dfd = store::open_directory(dir);
  std::string bytes = store::read_regular_file(dfd.get(), name, limit, "image", dir);
  return bytes;
}

void check_size(int w, int h, const std::string& source) {
  if (w <= 0 || h <= 0) throw FileError(source, "image has no pixels (" + std::to_string(w) + "x" + std::to_string(h) + ")");
  if (w > store::kMaxImageSide || h > store::kMaxImageSide || std::int64_t(w) * h > store::kMaxImagePixels)
    throw FileError(source, "image is " + std::to_string(w) + "x" + std::to_string(h) + ", larger than a Panoptes database allows (" +
                                std::to_string(store::kMaxImageSide) + " per side, " + std::to_string(store::kMaxImagePixels) +
                                " pixels)");
}

// libjpeg reports errors through a callback that must not return: it jumps back here. Nothing with a
// destructor lives between setjmp and the jump (C types only), so the jump skips no C++ cleanup.
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void jpeg_fail(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegError*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

void jpeg_quiet(j_common_ptr, int) {}

// Reads the header (out == nullptr) or the RGBA pixels into out (width * height * 4 bytes, the size
// a previous header call gave). Returns false with `message` set on any error.
bool jpeg_run(const std::uint8_t* data, std::size_t size, std::uint8_t* out, int* width, int* height, char* message) {
  jpeg_decompress_struct cinfo;
  JpegError err;
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = jpeg_fail;
  err.mgr.emit_message = jpeg_quiet;
  err.message[0] = 0;
  if (setjmp(err.jump)) {
    jpeg_destroy_decompress(&cinfo);
    std::snprintf(message, JMSG_LENGTH_MAX, "%s", err.message);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  if (!out) {
    *width = int(cinfo.image_width);
    *height = int(cinfo.image_height);
    jpeg_destroy_decompress(&cinfo);
    return true;
  }
  cinfo.out_color_space = JCS_EXT_RGBA;
  jpeg_start_decompress(&cinfo);
  if (int(cinfo.output_width) != *width || int(cinfo.output_height) != *height || cinfo.output_components != 4) {
    std::snprintf(message, JMSG_LENGTH_MAX, "decoded size differs from the header");
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = out + std::size_t(cinfo.output_scanline) * std::size_t(*width) * 4;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

void header_size(const std::uint8_t* d, std::size_t n, const std::string& source, int& w, int& h) {
  if (is_png(d, n)) {
    // Signature, then the IHDR chunk: length (4), "IHDR", width and height big-endian.
    if (n < 24 || std::memcmp(d + 12, "IHDR", 4) != 0) throw FileError(source, "not a readable PNG image: no IHDR chunk");
    const auto be = [&](std::size_t o) {
      return (std::uint32_t(d[o]) << 24) | (std::uint32_t(d[o + 1]) << 16) | (std::uint32_t(d[o + 2]) << 8) | d[o + 3];
    };
    const std::uint32_t bw = be(16), bh = be(20);
    if (bw > 0x7fffffffu || bh > 0x7fffffffu) throw FileError(source, "not a readable PNG image: size out of range");
    w = int(bw), h = int(bh);
  } else if (is_jpeg(d, n)) {
    char message[JMSG_LENGTH_MAX];
    if (!jpeg_run(d, n, nullptr, &w, &h, message)) throw FileError(source, std::string("not a readable JPEG image: ") + message);
  } else {
    throw FileError(source, "not a PNG or JPEG image");
  }
  check_size(w, h, source);
}

}  // namespace

void image_size(const fs::path& path, int& width, int& height) {
  const std::string bytes = read_bytes(path, kMaxImageFileBytes);
  header_size(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), path.string(), width, height);
}

Image decode_image_bytes(const std::uint8_t* d, std::size_t n, const std::string& source) {
  int w = 0, h = 0;
  header_size(d, n, source, w, h);
  Image img(w, h, 4);
  if (is_png(d, n)) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&png, d, n))
      throw FileError(source, std::string("not a readable PNG image: ") + png.message);
    png.format = PNG_FORMAT_RGBA;
    if (int(png.width) != w || int(png.height) != h) {
      png_image_free(&png);
      throw FileError(source, "not a readable PNG image: inconsistent size");
    }
    if (!png_image_finish_read(&png, nullptr, img.pixels.data(), 0, nullptr)) {
      const std::string why = png.message;
      png_image_free(&png);
      throw FileError(source, "not a readable PNG image: " + why);
    }
  } else {
    char message[JMSG_LENGTH_MAX];
    if (!jpeg_run(d, n, img.pixels.data(), &w, &h, message))
      throw FileError(source, std::string("not a readable JPEG image: ") + message);
  }
  return img;
}

Image decode_image(const fs::path& path, bool rotate180) {
  const std::string bytes = read_bytes(path, kMaxImageFileBytes);
  Image img = decode_image_bytes(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), path.string());
  if (rotate180) {
    // A 180-degree turn is the pixel order reversed (pixels, not bytes: channels stay in order).
    auto* p = reinterpret_cast<std::uint32_t*>(img.pixels.data());
    static_assert(sizeof(std::uint32_t) == 4);
    const std::size_t count = std::size_t(img.width) * std::size_t(img.height);
    for (std::size_t i = 0, j = count - 1; i < j; ++i, --j) {
      std::uint32_t a, b;
      std::memcpy(&a, p + i, 4);
      std::memcpy(&b, p + j, 4);
      std::memcpy(p + i, &b, 4);
      std::memcpy(p + j, &a, 4);
    }
  }
  return img;
}

}  // namespace panoptes::cinema
