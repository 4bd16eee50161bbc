#pragma once
// Rig specifications: a small struct and its string form, shared by `panoptes render`, `panoptes
// rig`, the in-situ configuration and the C API, plus the reader for explicit camera files.
//
// String syntax (whitespace around tokens is not allowed):
//   yinyang[:NTxNP]            Yin-Yang, NT x NP cells per patch (default 5x13 = 130 cameras;
//                              a few overlap cameras may be left out, see yinyang_pattern)
//   latlon[:NLATxNLON[+poles]] NLAT rings of NLON cameras, poles excluded unless "+poles"
//                              (default 8x16+poles = 130 cameras)
//   fibonacci[:N]              N-point golden-angle spiral (default 130)
//   file:PATH, or just PATH    explicit cameras from a text or JSON file (see read_rig_file)
//   lattice:NXxNYxNZ[@M]       cameras inside the volume at the nodes of an NX x NY x NZ lattice (cell
//                              centres of the domain shrunk by the fraction M at each face, default 0);
//                              world-axis navigation (camera/volume_rigs.hpp)
//   path:FILE                  cameras along a polyline read from FILE (camera/volume_rigs.hpp)
//   inshell[:NRxNP][@F1,F2,..] cameras inside a spherical shell: NR latitude rings of NP cameras (default
//                              4x12) on spheres of radius F x the domain's inscribed radius (default
//                              @0.675), looking along their ring, up = the local radial direction
// Any built-in kind may end with "@R1,R2,..." — shell radii in units of the domain's bounding-sphere
// radius (default @3); several radii repeat the pattern on shells, outermost = shell 0. A leading
// "shells:" is accepted for readability: "shells:yinyang@1.5,2.5,4".
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "camera/framing.hpp"
#include "camera/rig.hpp"

namespace panoptes::camera {

/// Largest camera file read_rig_file() accepts (about 10^7 cameras as text).
inline constexpr std::uint64_t kMaxRigFileBytes = 1ull << 30;

/// The kind and parameters of a rig.
struct RigSpec {
  enum class Kind { yinyang, latlon, fibonacci, file, lattice, path, inshell };
  Kind kind = Kind::yinyang;
  int rows = 5;        ///< yinyang: n_theta per patch; latlon, inshell: number of rings
  int columns = 13;    ///< yinyang: n_phi per patch; latlon: cameras per ring
  bool poles = false;  ///< latlon: add one camera at each pole
  int count = 130;     ///< fibonacci: number of points
  std::string path;    ///< file: the camera file; path: the polyline file
  std::array<int, 3> lattice{4, 4, 3};  ///< lattice: nodes along world x, y, z
  double margin = 0;                    ///< lattice: fraction of the extent kept free at each face
  std::vector<double> radii{kDefaultRadius};  ///< shell radii, bounding-sphere radii (not for file; inshell: inscribed radii)
  double fov_y_degrees = 0;                   ///< 0 = frame the domain from the outermost shell
  Vec3 up{0, 0, 0};                           ///< requested up of every camera; zero = the sky direction
  UpAxis up_axis = UpAxis::z_up;              ///< which way is up in the domain (not part of the string)

  /// Parses the string syntax above; throws panoptes::Error naming the text and what was expected.
  static RigSpec parse(std::string_view text);
  /// Canonical string form: parse(to_string()) gives the same spec (fov, up and up_axis are not part of it).
  std::string to_string() const;
  /// Cameras per shell (0 for file rigs, whose count is known only after reading the file).
  long long cameras_per_shell() const;
};

/// Builds the rig for a domain. Throws panoptes::Error / FileError on bad parameters or files.
Rig make_rig(const RigSpec& spec, const Domain& domain);
/// make_rig(RigSpec::parse(text), domain).
Rig make_rig(std::string_view text, const Domain& domain);

/// Reads an explicit camera list. Positions are world coordinates.
///  - JSON (a file whose first non-blank character is '{' or '['): either an array of cameras or
///    {"cameras": [...]}; each camera {"position": [x,y,z], optional "look_at": [x,y,z] (default: the
///    domain centre), "up": [x,y,z] (default: the sky direction of the spec's up_axis), "fov_y_degrees": f (default: the field of view
///    that frames the domain's bounding sphere from the camera's distance to the domain centre),
///    "shell": k (default 0), "patch": "name" (default "file")}.
///  - Text: one camera per line, numbers separated by blanks or commas, '#' starts a comment:
///    `x y z [lx ly lz [ux uy uz [fov [shell]]]]`.
/// Shell indices must cover 0..S−1 without gaps. Throws FileError naming the file, the line or
/// camera and the bad value.
/// Latitudes and longitudes are measured in the sky frame of `up_axis`.
Rig read_rig_file(const std::string& path, const Domain& domain, UpAxis up_axis = UpAxis::z_up);

}  // namespace panoptes::camera
