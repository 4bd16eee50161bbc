#pragma once
// A streaming GPU texture for planar YUV 4:2:0 frames: the renderer converts to RGB on the GPU (or in
// SDL's optimized software path), so the display path does no per-pixel colour conversion of its own.
#include <cstdint>

struct SDL_Renderer;
struct SDL_Texture;

namespace panoptes::ui {

/// Three planes of a 4:2:0 frame (BT.601 limited range), with their row pitches in bytes.
struct YuvPlanes {
  int width = 0, height = 0;
  const std::uint8_t* y = nullptr;
  const std::uint8_t* u = nullptr;
  const std::uint8_t* v = nullptr;
  int y_pitch = 0, u_pitch = 0, v_pitch = 0;
};

/// One SDL_PIXELFORMAT_IYUV streaming texture, re-created when the frame size changes.
class YuvTexture {
 public:
  explicit YuvTexture(SDL_Renderer* renderer) : renderer_(renderer) {}
  ~YuvTexture();
  YuvTexture(const YuvTexture&) = delete;
  YuvTexture& operator=(const YuvTexture&) = delete;

  /// Uploads a frame (SDL_UpdateYUVTexture). Throws panoptes::Error if SDL cannot create or update
  /// the texture.
  void upload(const YuvPlanes& planes);
  /// The texture (nullptr before the first upload).
  SDL_Texture* texture() const { return texture_; }
  int width() const { return width_; }
  int height() const { return height_; }
  /// The last uploaded frame converted to RGBA on the GPU (one render-to-texture pass of the frame's
  /// size, redone only after a new upload), or nullptr where the renderer has no render targets.
  /// Meant for drawings that sample the frame many times over, such as the look-around mesh: sampling
  /// one RGBA texture costs the software GL rasteriser far less than three planes plus the YUV→RGB
  /// conversion for every window pixel (measured in docs/measurements/ui.md).
  SDL_Texture* rgba();
  /// Nearest-neighbour sampling (to see individual pixels when zoomed far in) instead of linear.
  void set_pixelated(bool on);
  /// Number of uploads so far.
  std::int64_t uploads() const { return uploads_; }

 private:
  SDL_Renderer* renderer_;
  SDL_Texture* texture_ = nullptr;
  SDL_Texture* rgba_ = nullptr;
  bool rgba_current_ = false;
  int width_ = 0, height_ = 0;
  bool pixelated_ = false;
  std::int64_t uploads_ = 0;
};

}  // namespace panoptes::ui
