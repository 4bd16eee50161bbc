#pragma once
// Zoom and pan of the frame inside the window (pure maths, no SDL), so it can be tested exactly.
// Zoom 1 fits the whole frame in the viewport (aspect kept, centred); zoom z magnifies by z.
namespace panoptes::ui {

/// A rectangle in window pixels (floating point; the renderer rounds).
struct Rect {
  double x = 0, y = 0, w = 0, h = 0;
};

/// Where the frame is drawn: the frame point shown at the viewport centre and the magnification.
class ViewTransform {
 public:
  static constexpr double kMinZoom = 0.25;
  static constexpr double kMaxZoom = 64.0;

  /// Sets the viewport (window pixels) and frame size (frame pixels); keeps zoom and centre (the
  /// centre is re-clamped if the frame size changed).
  void set_sizes(double viewport_w, double viewport_h, double frame_w, double frame_h);
  /// Back to zoom 1, frame centred.
  void reset();

  double zoom() const { return zoom_; }
  /// Window pixels per frame pixel: fit scale × zoom.
  double scale() const;
  /// The frame's rectangle in window pixels (may extend beyond the viewport when zoomed in).
  Rect frame_rect() const;

  /// Frame coordinates (pixels, may lie outside the frame) of a window point, and back.
  void window_to_frame(double wx, double wy, double& fx, double& fy) const;
  void frame_to_window(double fx, double fy, double& wx, double& wy) const;

  /// Multiplies the zoom by `factor` (clamped to [kMinZoom, kMaxZoom]) keeping the frame point
  /// under the window point (wx, wy) fixed, as far as the pan clamp allows.
  void zoom_at(double factor, double wx, double wy);
  /// Moves the picture by (dx, dy) window pixels (right-drag). The frame centre stays inside the
  /// frame, so the picture can never be lost off-screen.
  void pan(double dx, double dy);

 private:
  void clamp_center();
  double vw_ = 1, vh_ = 1, fw_ = 1, fh_ = 1;
  double zoom_ = 1;
  double cx_ = 0.5, cy_ = 0.5;  // viewport centre, in frame coordinates relative to the frame size
};

}  // namespace panoptes::ui
