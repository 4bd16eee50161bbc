#include "ui/view_transform.hpp"

#include <algorithm>

namespace panoptes::ui {

void ViewTransform::set_sizes(double viewport_w, double viewport_h, double frame_w, double frame_h) {
  vw_ = std::max(1.0, viewport_w);
  vh_ = std::max(1.0, viewport_h);
  fw_ = std::max(1.0, frame_w);
  fh_ = std::max(1.0, frame_h);
  clamp_center();
}

void ViewTransform::reset() {
  zoom_ = 1;
  cx_ = cy_ = 0.5;
}

double ViewTransform::scale() const { return std::min(vw_ / fw_, vh_ / fh_) * zoom_; }

Rect ViewTransform::frame_rect() const {
  const double s = scale();
  return {vw_ / 2 - cx_ * fw_ * s, vh_ / 2 - cy_ * fh_ * s, fw_ * s, fh_ * s};
}

void ViewTransform::window_to_frame(double wx, double wy, double& fx, double& fy) const {
  const double s = scale();
  fx = cx_ * fw_ + (wx - vw_ / 2) / s;
  fy = cy_ * fh_ + (wy - vh_ / 2) / s;
}

void ViewTransform::frame_to_window(double fx, double fy, double& wx, double& wy) const {
  const double s = scale();
  wx = vw_ / 2 + (fx - cx_ * fw_) * s;
  wy = vh_ / 2 + (fy - cy_ * fh_) * s;
}

void ViewTransform::zoom_at(double factor, double wx, double wy) {
  if (!(factor > 0)) return;
  double fx, fy;
  window_to_frame(wx, wy, fx, fy);
  zoom_ = std::clamp(zoom_ * factor, kMinZoom, kMaxZoom);
  // Choose the centre so that (fx, fy) maps to (wx, wy) again at the new scale.
  const double s = scale();
  cx_ = (fx - (wx - vw_ / 2) / s) / fw_;
  cy_ = (fy - (wy - vh_ / 2) / s) / fh_;
  clamp_center();
}

void ViewTransform::pan(double dx, double dy) {
  const double s = scale();
  cx_ -= dx / s / fw_;
  cy_ -= dy / s / fh_;
  clamp_center();
}

void ViewTransform::clamp_center() {
  // At or below zoom 1 the whole frame fits: keep it centred, panning makes no sense there.
  if (zoom_ <= 1) {
    cx_ = cy_ = 0.5;
    return;
  }
  cx_ = std::clamp(cx_, 0.0, 1.0);
  cy_ = std::clamp(cy_, 0.0, 1.0);
}

}  // namespace panoptes::ui
