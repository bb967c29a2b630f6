// Luminaires from manufacturers' photometric files: IES LM-63 (1986, 1991, 1995, 2002 and 2019
// headers) and EULUMDAT (.ldt), type C photometry. A file becomes a table of luminous intensity
// in candela over the whole sphere, indexed by the horizontal angle C (0 to 360 degrees, the
// symmetries the file declares unfolded) and the vertical angle gamma (0 at the nadir, 180
// straight up), read by bilinear interpolation; zero outside the vertical angles the file covers.
//
// The luminaire's frame: gamma 0 (the nadir) along -y, C 0 along +x, C 90 along +z. It is the
// frame of pbrt-v4's goniometric light, whose image centre is the light's +y (the luminaire's
// zenith), so that goniometric_image() gives the image pbrt-v4 expects. pbrt-v4's coordinates are
// left-handed (a camera that looks down -z with +y up sees +x on its left), so C runs
// counterclockwise seen from above, as LM-63 defines it, in a scene whose up is +y as it stands,
// and in one whose up is +z after "Rotate 90 1 0 0" (nadir along -z, C 90 along -y).
#pragma once
#include <string>
#include <vector>

#include "base/error.h"
#include "base/vec.h"

namespace bpm {

struct PhotometricData {
  std::string path;
  std::string format;  // "IES LM-63-2002", "EULUMDAT", ...
  std::string name;    // the luminaire's name or catalogue number, when the file gives one
  // Angles in degrees, ascending: c covers [0, 360] (the last plane repeats the first), gamma a
  // part of [0, 180]. candela[i * gamma.size() + j] is the intensity at (c[i], gamma[j]).
  std::vector<double> c, gamma;
  std::vector<double> candela;
  // The lamps' rated flux as the file states it (IES: lamps x lumens per lamp; EULUMDAT: the
  // first lamp set's flux); 0 for absolute photometry (IES lumens per lamp of -1).
  double lamp_lumens = 0;

  // Luminous intensity (cd) toward (C, gamma) in degrees.
  double intensity(double c_deg, double gamma_deg) const;
  // Luminous intensity (cd) toward a direction of the luminaire's frame (above), unit length.
  double intensity(Vec3 w) const;
  // Luminous flux (lm): the intensity integrated over the sphere.
  double luminous_flux() const;
};

// Reads an IES LM-63 file. Errors name the file, the line and what is wrong.
PhotometricData read_ies(const std::string& path);
PhotometricData parse_ies(const std::string& text, const std::string& path);
// Reads a EULUMDAT file.
PhotometricData read_eulumdat(const std::string& path);
PhotometricData parse_eulumdat(const std::string& text, const std::string& path);
// By extension: .ies, or .ldt (any case).
PhotometricData read_photometric_file(const std::string& path);
bool is_photometric_file(const std::string& path);

// The side of the image a goniometric light makes of a photometric file, and of the image `bpm
// luminaire` writes by default: about 0.4 degrees a texel.
constexpr int kLuminaireImageSize = 512;

// The equal-area octahedral image (n x n, one value a texel: candela toward the texel's centre)
// that pbrt-v4's goniometric light reads with nearest-texel lookups, in the frame above.
std::vector<float> goniometric_image(const PhotometricData& d, int n);
// The direction of the luminaire's frame for an image's (u, v) in [0, 1]^2, v down.
Vec3 goniometric_image_direction(Vec2 uv);

}  // namespace bpm
