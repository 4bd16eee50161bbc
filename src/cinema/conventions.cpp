#include "cinema/conventions.hpp"

#include <algorithm>
#include <cmath>

#include "camera/framing.hpp"
#include "cinema/csv.hpp"
#include "core/error.hpp"

namespace panoptes::cinema {

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
// The stand-in scene when the database does not record one: a unit box at the origin, whose
// bounding sphere has this radius. Distances are then in the producer's own units of that sphere.
const double kUnitSphere = std::sqrt(3.0) / 2.0;

const char* kAsk =
    "; say how its angles were made with --angles paraview|cinema-python|ascent|elevation (and, for "
    "elevation, --azimuth-zero +x|-x)";

Vec3 axis_vector(int a) { return a == 0 ? Vec3{1, 0, 0} : a == 1 ? Vec3{0, 1, 0} : Vec3{0, 0, 1}; }

// A view up made orthogonal to the view direction, as VTK renders a non-orthogonal one.
Vec3 orthogonal_up(const Vec3& up, const Vec3& forward) {
  const Vec3 u = up - forward * dot(up, forward);
  return norm(u) > 1e-12 ? normalize(u) : up;
}

Vec3 vec_at(const nlohmann::json& list, std::size_t i, const std::string& what) {
  if (!list.is_array() || i >= list.size() || !list[i].is_array() || list[i].size() != 3)
    throw Error("info.json metadata." + what + "[" + std::to_string(i) + "]: expected [x, y, z]");
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    if (!list[i][std::size_t(k)].is_number())
      throw Error("info.json metadata." + what + "[" + std::to_string(i) + "]: expected numbers");
    v[k] = list[i][std::size_t(k)].get<double>();
    if (!std::isfinite(v[k])) throw Error("info.json metadata." + what + ": not finite");
  }
  return v;
}

// cinema_python records the camera it turns around (camera_eye, camera_at, camera_up, camera_angle),
// one entry per time step. Panoptes cameras do not move with time: all entries must agree.
void recorded_cinema_python(const nlohmann::json& meta, int times, CameraModel& m) {
  for (const char* key : {"camera_eye", "camera_at", "camera_up"})
    if (!meta.contains(key) || !meta[key].is_array() || meta[key].empty())
      throw Error(std::string("info.json metadata has no ") + key +
                  "; cinema_python records the camera it turns around there" + kAsk);
  const nlohmann::json &eye = meta["camera_eye"], &at = meta["camera_at"], &up = meta["camera_up"];
  const Vec3 e0 = vec_at(eye, 0, "camera_eye"), a0 = vec_at(at, 0, "camera_at"), u0 = vec_at(up, 0, "camera_up");
  const std::size_t n = std::min({eye.size(), at.size(), up.size(), std::size_t(std::max(times, 1))});
  for (std::size_t i = 1; i < n; ++i) {
    const double scale = std::max(1.0, norm(e0 - a0));
    if (norm(vec_at(eye, i, "camera_eye") - e0) > 1e-6 * scale || norm(vec_at(at, i, "camera_at") - a0) > 1e-6 * scale ||
        norm(vec_at(up, i, "camera_up") - u0) > 1e-6)
      throw Error("info.json metadata: the recorded camera moves between time steps (camera_eye/at/up entry " +
                  std::to_string(i) + " differs from entry 0); Panoptes cameras are fixed over time");
  }
  m.center = a0;
  m.distance = norm(e0 - a0);
  if (!(m.distance > 0)) throw Error("info.json metadata: camera_eye equals camera_at; no distance to turn at");
  if (!(m.distance < 1e100 && norm(a0) < 1e100)) throw Error("info.json metadata: camera_eye/camera_at out of range");
  // pv_introspect.explore: the rotation axis is the world axis closest to the recorded view up.
  int best = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(u0[k]) > std::abs(u0[best])) best = k;
  m.pole = axis_vector(best);
  if (meta.contains("camera_angle") && meta["camera_angle"].is_array() && !meta["camera_angle"].empty() &&
      meta["camera_angle"][0].is_number()) {
    const double a = meta["camera_angle"][0].get<double>();
    if (a > 0 && a < 180) m.fov_y_deg = a;
  }
  m.recorded = true;
}

}  // namespace

Angles parse_angles(const std::string& t) {
  if (t == "paraview") return Angles::paraview;
  if (t == "cinema-python") return Angles::cinema_python;
  if (t == "ascent") return Angles::ascent;
  if (t == "elevation") return Angles::elevation;
  throw Error("--angles \"" + t + "\"; expected paraview, cinema-python, ascent or elevation");
}

std::string to_string(Angles a) {
  switch (a) {
    case Angles::paraview: return "paraview";
    case Angles::cinema_python: return "cinema-python";
    case Angles::ascent: return "ascent";
    case Angles::elevation: return "elevation";
  }
  return "?";
}

ProducerCamera producer_camera(const CameraModel& m, double phi_deg, double theta_deg) {
  const double p = phi_deg * kDeg, t = theta_deg * kDeg;
  Vec3 dir, up;
  switch (m.angles) {
    case Angles::paraview: {
      // Azimuth(phi) about +y from +z, then Elevation(theta) about the camera's right axis (rigid:
      // the view up turns with it; OrthogonalizeViewUp keeps it so).
      const Vec3 n1{std::sin(p), 0, std::cos(p)}, y{0, 1, 0};
      dir = n1 * std::cos(t) + y * std::sin(t);
      up = n1 * -std::sin(t) + y * std::cos(t);
      break;
    }
    case Angles::cinema_python: {
      // pv_explorers.Camera.execute for rotation axis z; other axes rotate the components first.
      Vec3 b{std::cos(p) * std::cos(t), std::sin(p) * std::cos(t), std::sin(t)};
      Vec3 u{std::cos(p) * std::sin(t), -std::sin(p) * std::sin(t), std::cos(t)};
      const int axis = m.pole.x != 0 ? 0 : m.pole.y != 0 ? 1 : 2;
      for (int k = 0; k < (axis + 1) % 3; ++k) {
        b = {b.z, b.x, b.y};
        u = {u.z, u.x, u.y};
      }
      dir = {-b.x, b.y, b.z};  // its position mirrors x; the view up it sets does not
      up = u;
      break;
    }
    case Angles::ascent: {
      // RotateZ(phi) * RotateX(theta) applied to (0, 0, 1) and to (0, 1, 0); an older Ascent's
      // latitude-style theta is first turned into the polar angle.
      const double a = m.latitude_theta ? (90 - theta_deg) * kDeg : t;
      dir = {std::sin(a) * std::sin(p), -std::sin(a) * std::cos(p), std::cos(a)};
      up = {-std::cos(a) * std::sin(p), std::cos(a) * std::cos(p), std::sin(a)};
      break;
    }
    case Angles::elevation: {
      const double s = m.mirrored ? -1 : 1;
      const Vec3 h{s * std::cos(p), std::sin(p), 0};
      dir = h * std::cos(t) + Vec3{0, 0, std::sin(t)};
      up = h * -std::sin(t) + Vec3{0, 0, std::cos(t)};
      break;
    }
  }
  ProducerCamera c;
  dir = normalize(dir);
  c.look_at = m.center;
  c.position = m.center + dir * m.distance;
  c.up = orthogonal_up(up, -dir);
  c.rotated = dot(c.up, m.pole) < -1e-9;
  c.stored_up = c.rotated ? -c.up : c.up;
  return c;
}

CameraModel detect_producer(const ProducerEvidence& e, const std::string& angles, const std::string& azimuth_zero) {
  CameraModel m;
  const nlohmann::json* meta = e.info && e.info->is_object() && e.info->contains("metadata") &&
                                       (*e.info)["metadata"].is_object()
                                   ? &(*e.info)["metadata"]
                                   : nullptr;
  const bool has_arguments = e.info && e.info->is_object() && e.info->contains("arguments");
  const std::string version = e.info && e.info->is_object() && e.info->contains("version") && (*e.info)["version"].is_string()
                                  ? (*e.info)["version"].get<std::string>()
                                  : "";
  const std::string pattern = e.info && e.info->is_object() && e.info->contains("name_pattern") &&
                                      (*e.info)["name_pattern"].is_string()
                                  ? (*e.info)["name_pattern"].get<std::string>()
                                  : "";
  const bool phi_theta_model = meta && meta->contains("camera_model") && (*meta)["camera_model"] == "phi-theta";
  const bool has_producer_column = std::find(e.columns.begin(), e.columns.end(), "producer") != e.columns.end();
  if (!azimuth_zero.empty() && azimuth_zero != "+x" && azimuth_zero != "-x")
    throw Error("--azimuth-zero \"" + azimuth_zero + "\"; expected +x or -x");

  // Every piece of evidence names a convention; they must agree.
  struct Clue {
    Angles angles;
    std::string text;
  };
  std::vector<Clue> clues;
  if (e.file_column.size() > 5 && e.file_column.rfind("FILE_", 0) == 0)
    clues.push_back({Angles::paraview, "data.csv names its image column " + e.file_column +
                                           (has_producer_column ? " and has a producer column" : "") + " (ParaView image extractor)"});
  if (phi_theta_model) clues.push_back({Angles::cinema_python, "info.json metadata.camera_model is \"phi-theta\" (cinema_python)"});
  if (has_arguments && (e.has_info_js || (version == "1.1" && pattern.rfind("{time}/{phi}_{theta}_", 0) == 0)))
    clues.push_back({Angles::ascent, e.has_info_js
                                         ? "info.json keeps its parameters under \"arguments\" and info.js (Ascent's viewer data) is present"
                                         : "info.json version 1.1 with \"arguments\" and name_pattern " + pattern + " (Ascent)"});
  if (!angles.empty()) {
    m.angles = parse_angles(angles);
    m.evidence = "--angles " + angles;
  } else if (!clues.empty()) {
    for (const Clue& c : clues)
      if (c.angles != clues[0].angles)
        throw Error("the evidence disagrees on how phi/theta were made: " + clues[0].text + ", but " + c.text +
                    "; say which with --angles " + to_string(clues[0].angles) + "|" + to_string(c.angles));
    if (e.layout && *e.layout != clues[0].angles)
      throw Error("the evidence disagrees on how phi/theta were made: " + clues[0].text + ", but the " + e.layout_text +
                  " as " + (*e.layout == Angles::paraview ? "ParaView's image extractor" : *e.layout == Angles::ascent ? "Ascent" : "cinema_python") +
                  " names them; say which with --angles " + to_string(clues[0].angles) + "|" + to_string(*e.layout));
    m.angles = clues[0].angles;
    for (const Clue& c : clues) m.evidence += (m.evidence.empty() ? "" : "; ") + c.text;
    if (e.layout) m.evidence += "; " + e.layout_text;
  } else if (e.thetas.empty()) {
    m.angles = Angles::elevation;  // no theta: one camera ring or one camera, nothing to confuse
    m.evidence = "no theta column";
  } else {
    std::string seen = "spec " + e.spec + ", image column " + e.file_column;
    if (e.info) seen += has_arguments ? ", info.json with \"arguments\"" : ", info.json with \"parameter_list\"";
    if (!version.empty()) seen += ", version " + version;
    if (e.layout) seen += ", " + e.layout_text;
    throw Error("cannot tell which producer's phi/theta convention this Cinema database uses (" + seen +
                "): ParaView extracts, cinema_python, Ascent and others build different cameras from the same angles" + kAsk);
  }
  if (!azimuth_zero.empty() && m.angles != Angles::elevation)
    throw Error("--azimuth-zero applies to --angles elevation only; the " + to_string(m.angles) +
                " convention fixes its own azimuth");
  m.mirrored = azimuth_zero == "-x";

  switch (m.angles) {
    case Angles::paraview:
      // vtkRenderer::ResetCamera frames the bounding sphere: distance = radius / sin(view angle / 2);
      // ParaView's view angle is 30 degrees; the pole is +y.
      m.producer = "ParaView image extractor (camera mode Phi-Theta)";
      m.fov_y_deg = 30;
      m.distance = kUnitSphere / std::sin(15 * kDeg);
      m.pole = {0, 1, 0};
      break;
    case Angles::cinema_python:
      m.producer = "ParaView cinema_python (phi-theta camera)";
      m.fov_y_deg = 30;
      m.distance = kUnitSphere / std::sin(15 * kDeg);
      m.pole = {0, 0, 1};
      if (meta && meta->contains("camera_eye")) recorded_cinema_python(*meta, e.time_count, m);
      break;
    case Angles::ascent:
      // CinemaManager: radius = |bounds extent| * 2.5 / 2 = 2.5 bounding-sphere radii; vtkm's default
      // field of view is 60 degrees.
      m.producer = "Ascent cinema extract";
      m.fov_y_deg = 60;
      m.distance = 2.5 * kUnitSphere;
      m.pole = {0, 0, 1};
      // Ascent writes theta as a polar angle from +z (0..180); older releases wrote a latitude
      // (-90..90). A negative theta tells them apart; a range that fits neither is refused.
      if (!e.thetas.empty() && e.thetas.front() < -1e-9) {
        if (e.thetas.front() < -90 - 1e-9 || e.thetas.back() > 90 + 1e-9)
          throw Error("theta runs " + format_float(e.thetas.front()) + ".." + format_float(e.thetas.back()) +
                      ", neither a polar angle in 0..180 (Ascent) nor a latitude in -90..90 (older Ascent)" + kAsk);
        m.latitude_theta = true;
        m.producer += " (theta as a latitude, -90..90)";
        m.notes.push_back("theta runs " + format_float(e.thetas.front()) + ".." + format_float(e.thetas.back()) +
                          ": read as a latitude as older Ascent wrote it (polar angle = 90 - theta; --angles elevation "
                          "reads it as an elevation about +z instead)");
      }
      for (double t : e.thetas)
        if (!m.latitude_theta && (t < -1e-9 || t > 180 + 1e-9))
          throw Error("theta " + format_float(t) + " is not a polar angle in 0..180 as Ascent writes it" + kAsk);
      break;
    case Angles::elevation:
      m.producer = "generic Cinema (theta = elevation)";
      m.distance = camera::kDefaultRadius * kUnitSphere;
      m.fov_y_deg = camera::fit_fov_y_degrees(m.distance, kUnitSphere);
      m.pole = {0, 0, 1};
      for (double t : e.thetas)
        if (t < -90 - 1e-9 || t > 90 + 1e-9)
          throw Error("theta " + format_float(t) + " is not an elevation in -90..90 degrees" + kAsk);
      break;
  }
  return m;
}

}  // namespace panoptes::cinema
