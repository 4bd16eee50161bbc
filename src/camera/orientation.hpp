#pragma once
// Which way is up in a domain. Seismology (and the demo) measure z as depth, positive DOWN; most other
// simulations have z up. A rig is laid out in a "sky frame" whose north pole is the sky, so its poles,
// latitudes, camera up vectors and the navigation graph's Up all point towards the sky in either case.
#include <string_view>

#include "core/vec3.hpp"

namespace panoptes::camera {

/// The world direction that is "up" (towards the sky) in a domain.
enum class UpAxis {
  z_up,    ///< +z is up (the default, and what databases without an orientation mean)
  z_down,  ///< z is depth, positive down: −z is up (seismology)
};

/// "z_up" / "z_down".
std::string_view to_string(UpAxis axis);
/// Parses "z_up" or "z_down"; throws panoptes::Error naming the text otherwise.
UpAxis parse_up_axis(std::string_view text);

/// A right-handed orthonormal frame (east, north, sky) of the world: rig patterns are defined with
/// +z = sky and mapped into the world with to_world(). For z_up it is the identity; for z_down
/// east = +y, north = +x, sky = −z (x = north, y = east, z = depth, as Aki & Richards), so a map seen
/// from the sky has east to the right and north up.
struct SkyFrame {
  Vec3 east{1, 0, 0}, north{0, 1, 0}, sky{0, 0, 1};

  static SkyFrame of(UpAxis axis);
  /// Pattern coordinates (x = east, y = north, z = sky) → world direction.
  Vec3 to_world(const Vec3& p) const { return east * p.x + north * p.y + sky * p.z; }
  /// World direction → pattern coordinates.
  Vec3 to_local(const Vec3& d) const { return {dot(d, east), dot(d, north), dot(d, sky)}; }
};

/// Latitude (towards the sky) and longitude (from east towards north) of a world direction, degrees.
void sky_latitude_longitude(const SkyFrame& frame, const Vec3& direction, double& latitude_deg, double& longitude_deg);

}  // namespace panoptes::camera
