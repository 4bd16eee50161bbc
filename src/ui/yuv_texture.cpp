#include "ui/yuv_texture.hpp"

#include <SDL.h>

#include <string>

#include "core/error.hpp"

namespace panoptes::ui {

YuvTexture::~YuvTexture() {
  if (rgba_) SDL_DestroyTexture(rgba_);
  if (texture_) SDL_DestroyTexture(texture_);
}

void YuvTexture::set_pixelated(bool on) {
  const SDL_ScaleMode mode = on ? SDL_ScaleModeNearest : SDL_ScaleModeLinear;
  if (texture_ && on != pixelated_) SDL_SetTextureScaleMode(texture_, mode);
  if (rgba_ && on != pixelated_) SDL_SetTextureScaleMode(rgba_, mode);
  pixelated_ = on;
}

SDL_Texture* YuvTexture::rgba() {
  if (!texture_ || !SDL_RenderTargetSupported(renderer_)) return nullptr;
  if (!rgba_) {
    rgba_ = SDL_CreateTexture(renderer_, SDL_PIXELFORMAT_ABGR8888, SDL_TEXTUREACCESS_TARGET, width_, height_);
    if (!rgba_) return nullptr;
    SDL_SetTextureScaleMode(rgba_, pixelated_ ? SDL_ScaleModeNearest : SDL_ScaleModeLinear);
    rgba_current_ = false;
  }
  if (!rgba_current_) {
    SDL_Texture* previous = SDL_GetRenderTarget(renderer_);
    if (SDL_SetRenderTarget(renderer_, rgba_) != 0) return nullptr;
    SDL_BlendMode blend = SDL_BLENDMODE_NONE;
    SDL_GetTextureBlendMode(texture_, &blend);
    SDL_SetTextureBlendMode(texture_, SDL_BLENDMODE_NONE);
    SDL_RenderCopy(renderer_, texture_, nullptr, nullptr);
    SDL_SetTextureBlendMode(texture_, blend);
    SDL_SetRenderTarget(renderer_, previous);
    rgba_current_ = true;
  }
  return rgba_;
}

void YuvTexture::upload(const YuvPlanes& p) {
  if (p.width <= 0 || p.height <= 0 || !p.y || !p.u || !p.v)
    throw Error("YUV frame to display is empty (" + std::to_string(p.width) + "x" + std::to_string(p.height) + ")");
  if (!texture_ || p.width != width_ || p.height != height_) {
    if (texture_) SDL_DestroyTexture(texture_);
    if (rgba_) SDL_DestroyTexture(rgba_);
    rgba_ = nullptr;
    // The movies are BT.601 limited range (see video::YuvFrame); tell SDL so its conversion matches.
    SDL_SetYUVConversionMode(SDL_YUV_CONVERSION_BT601);
    texture_ = SDL_CreateTexture(renderer_, SDL_PIXELFORMAT_IYUV, SDL_TEXTUREACCESS_STREAMING, p.width, p.height);
    if (!texture_)
      throw Error("cannot create a " + std::to_string(p.width) + "x" + std::to_string(p.height) +
                  " YUV texture: " + SDL_GetError());
    width_ = p.width;
    height_ = p.height;
    pixelated_ = !pixelated_;
    set_pixelated(!pixelated_);
  }
  if (SDL_UpdateYUVTexture(texture_, nullptr, p.y, p.y_pitch, p.u, p.u_pitch, p.v, p.v_pitch) != 0)
    throw Error(std::string("cannot upload a YUV frame to the GPU: ") + SDL_GetError());
  rgba_current_ = false;
  ++uploads_;
}

}  // namespace panoptes::ui
