#pragma once
// How Cinema producers turn (phi, theta) into a camera. Cinema databases record only the two angles;
// each producer builds its camera from them differently, and a wrong guess imports a database
// mirrored, upside down or with the pole on the equator. So the producer is recognised from what it
// writes (detect_producer), its own construction computes each image's camera (producer_camera), and
// a database whose convention cannot be told apart is refused with the option that settles it.
// Conventions and the evidence for each: docs/formats.md, "Cinema databases".
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/vec3.hpp"

namespace panoptes::cinema {

/// The (phi, theta) conventions Panoptes knows.
enum class Angles {
  /// ParaView 5.11 image extractors, camera mode Phi-Theta (vtkSMImageExtractWriterProxy): the camera
  /// starts on +z of the focal point with view up +y, Azimuth(phi) turns it about +y, then
  /// Elevation(theta) over the +y pole (theta 0..360: past 90 the view is upside down).
  paraview,
  /// ParaView's cinema_python phi-theta camera (pv_explorers.Camera): theta an elevation about the
  /// view's most upward world axis, phi an azimuth from the -x side (mirrored against +x).
  cinema_python,
  /// Ascent's cinema extract (CinemaManager): theta a polar angle from +z (0..180), phi about +z,
  /// camera = RotateZ(phi) * RotateX(theta) applied to (0, 0, 1), view up the same rotation of +y.
  ascent,
  /// Generic: theta an elevation in -90..90 above the x-y plane, phi an azimuth about +z from the
  /// azimuth-zero axis (+x counter-clockwise seen from +z, or -x clockwise), view up towards +z.
  elevation,
};

/// Parses "paraview", "cinema-python", "ascent", "elevation"; throws Error naming the value otherwise.
Angles parse_angles(const std::string& text);
/// The option value of a convention ("paraview", ...).
std::string to_string(Angles a);

/// Where a database's cameras are and how they are built.
struct CameraModel {
  Angles angles = Angles::elevation;
  std::string producer;            ///< e.g. "ParaView 5.11 image extractor (Phi-Theta)"
  std::string evidence;            ///< why: "data.csv has the column FILE_png", "--angles ascent"
  bool mirrored = false;           ///< elevation only: azimuth zero on -x, phi turning clockwise
  Vec3 center{0, 0, 0};            ///< focal point of every camera
  double distance = 0;             ///< camera to focal point
  Vec3 pole{0, 0, 1};              ///< the producer's "up" axis (unit, a world axis)
  double fov_y_deg = 30;           ///< vertical view angle
  bool recorded = false;           ///< center, distance, pole and fov come from recorded camera metadata
  /// ascent only: theta is a latitude in -90..90 (older Ascent), the polar angle is 90 - theta.
  bool latitude_theta = false;
  std::vector<std::string> notes;  ///< what the user should be told (e.g. latitude-style theta)
};

/// One image's camera as the producer built it, and how Panoptes stores it.
struct ProducerCamera {
  Vec3 position, look_at;
  Vec3 up;                 ///< the producer's view up (orthogonal to the view direction)
  Vec3 stored_up;          ///< the view up Panoptes stores: `up`, or -up when the image is turned
  bool rotated = false;    ///< the producer's picture is upside down (its up points away from the
                           ///< pole): stored turned by 180 degrees, so it is shown upright
};

/// The producer's camera for (phi, theta) in degrees.
ProducerCamera producer_camera(const CameraModel& model, double phi, double theta);

/// What detect_producer looks at: the table's columns and, when present, info.json and whether
/// info.js exists (Ascent copies its viewer next to the database).
struct ProducerEvidence {
  std::string spec;                       ///< "D" or "A"
  std::vector<std::string> columns;       ///< parameter columns
  std::string file_column;                ///< "FILE" or "FILE_png", ...
  std::optional<nlohmann::json> info;     ///< info.json, if the database has one
  bool has_info_js = false;
  std::vector<double> thetas;             ///< the distinct theta values (empty: no theta column)
  int time_count = 1;                     ///< distinct times (to check per-time recorded cameras)
  /// How the image files are named, when every row's path carries its phi and theta as one producer
  /// names them (import.cpp, file_layout): ParaView's extractor "...p=PHIt=THETA.png", cinema_python's
  /// ".../PHI/THETA[/...].png", Ascent's "TIME/PHI_THETA_NAME.png". Corroborates or contradicts the
  /// other evidence; alone it does not decide (a generic layout a user may have chosen).
  std::optional<Angles> layout;
  std::string layout_text;                ///< e.g. "files named image/{phi}/{theta}.png (image/30/45.png)"
};

/// The camera model of a database: `angles` (the --angles option, empty = detect) and `azimuth_zero`
/// ("+x", "-x" or empty) decide if given; else the producer is recognised from all of `e` (image
/// column name, info.json, info.js, file layout). Throws Error, naming what was seen and the options
/// to pass, when the convention is unknown, when two pieces of evidence name different producers, when
/// theta values do not fit the convention, or when recorded camera metadata is malformed.
CameraModel detect_producer(const ProducerEvidence& e, const std::string& angles, const std::string& azimuth_zero);

}  // namespace panoptes::cinema
