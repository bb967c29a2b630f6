// Tests of the photometric file readers: IES LM-63 and EULUMDAT tables unfolded by their
// symmetries, the luminous flux against closed forms, the goniometric image, and located errors.
#include "lights/photometric_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

namespace bpm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// An IES LM-63-2002 file: header, then the numbers.
std::string ies(const std::string& numbers, const std::string& tilt = "TILT=NONE") {
  return "IESNA:LM-63-2002\n[TEST] unit\n[MANUFAC] bpm\n[LUMINAIRE] test luminaire\n" + tilt +
         "\n" + numbers;
}

// A table over vertical angles 0, 1, ..., 180 (or 0..90) of f(gamma), one horizontal angle.
std::string rotational_ies(int last_gamma, double (*f)(double), double multiplier = 1,
                           double lumens = -1) {
  std::ostringstream s;
  s << "1 " << lumens << " " << multiplier << " " << last_gamma + 1 << " 1 1 2 0 0 0\n1 1 0\n";
  for (int g = 0; g <= last_gamma; ++g) s << g << (g % 10 == 9 ? "\n" : " ");
  s << "\n0\n";
  for (int g = 0; g <= last_gamma; ++g) s << f(g) << (g % 10 == 9 ? "\n" : " ");
  return ies(s.str());
}

double constant_100(double) { return 100; }
double cosine_1000(double g) { return 1000 * std::cos(g * kPi / 180); }

std::string error_of(const std::string& text, bool eulumdat = false) {
  try {
    if (eulumdat)
      parse_eulumdat(text, "lamp.ldt");
    else
      parse_ies(text, "lamp.ies");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PhotometricFile, IsotropicIesEmitsFourPiTimesItsIntensity) {
  PhotometricData d = parse_ies(rotational_ies(180, constant_100, 2.0), "iso.ies");
  EXPECT_EQ(d.format, "IES LM-63-2002");
  EXPECT_EQ(d.name, "test luminaire");
  EXPECT_EQ(d.lamp_lumens, 0);                  // absolute photometry
  EXPECT_NEAR(d.intensity(37, 91), 200, 1e-9);  // the multiplier applies
  EXPECT_NEAR(d.luminous_flux(), 4 * kPi * 200, 1e-6 * 4 * kPi * 200);
}

TEST(PhotometricFile, LambertianDownlightEmitsPiTimesItsPeak) {
  PhotometricData d = parse_ies(rotational_ies(90, cosine_1000, 1, 1000), "cos.ies");
  EXPECT_EQ(d.lamp_lumens, 1000);
  EXPECT_NEAR(d.intensity(0, 0), 1000, 1e-9);
  EXPECT_EQ(d.intensity(0, 120), 0);  // above the table: dark
  // Straight down in the luminaire's frame is -y.
  EXPECT_NEAR(d.intensity(Vec3(0, -1, 0)), 1000, 1e-6);
  // The bilinear table of a cosine at 1 degree steps: within 1e-4 of pi I0.
  EXPECT_NEAR(d.luminous_flux(), kPi * 1000, 1e-4 * kPi * 1000);
}

// A quadrant-symmetric file (horizontal angles 0 to 90) unfolds to I(180 - C) = I(C) and
// I(360 - C) = I(C); a bilateral one (0 to 180) to I(360 - C) = I(C).
TEST(PhotometricFile, IesSymmetriesUnfold) {
  const std::string quadrant =
      ies("1 -1 1 2 3 1 2 0 0 0\n1 1 0\n0 90\n0 45 90\n"
          "10 20\n30 40\n50 60\n");
  PhotometricData q = parse_ies(quadrant, "q.ies");
  for (double c : {10.0, 30.0, 60.0, 85.0}) {
    const double v = q.intensity(c, 45);
    EXPECT_NEAR(q.intensity(180 - c, 45), v, 1e-9) << c;
    EXPECT_NEAR(q.intensity(180 + c, 45), v, 1e-9) << c;
    EXPECT_NEAR(q.intensity(360 - c, 45), v, 1e-9) << c;
  }
  EXPECT_NEAR(q.intensity(45, 90), 40, 1e-9);
  EXPECT_NEAR(q.intensity(22.5, 0), 20, 1e-9);  // halfway between the planes at 0 and 45
  const std::string bilateral =
      ies("1 -1 1 2 3 1 2 0 0 0\n1 1 0\n0 90\n0 90 180\n"
          "10 20\n30 40\n50 60\n");
  PhotometricData b = parse_ies(bilateral, "b.ies");
  EXPECT_NEAR(b.intensity(270, 90), 40, 1e-9);
  EXPECT_NEAR(b.intensity(300, 0), b.intensity(60, 0), 1e-9);
  // C 90 lies along +z of the luminaire's frame, C 270 along -z.
  EXPECT_NEAR(b.intensity(Vec3(0, 0, 1)), 40, 1e-6);
  // An asymmetric file: 0 to 270 degrees, back to the plane at 0 by 360.
  PhotometricData a =
      parse_ies(ies("1 -1 1 2 4 1 2 0 0 0\n1 1 0\n0 90\n0 90 180 270\n1 1\n2 2\n3 3\n4 4\n"), "a");
  EXPECT_NEAR(a.intensity(315, 30), 2.5, 1e-9);
  // 1995's 90 to 270: symmetric about the 90-270 plane.
  PhotometricData h =
      parse_ies(ies("1 -1 1 2 3 1 2 0 0 0\n1 1 0\n0 90\n90 180 270\n1 1\n2 2\n3 3\n"), "h");
  EXPECT_NEAR(h.intensity(0, 10), 2, 1e-9);
  EXPECT_NEAR(h.intensity(45, 10), 1.5, 1e-9);
  EXPECT_NEAR(h.intensity(315, 10), 2.5, 1e-9);
}

// The thirteenth number scales the candela values in 1995 and earlier files (the ballast-lamp
// factor); in 2002 it is for future use and in 2019 it says how the file was made.
TEST(PhotometricFile, BallastLampFactorScalesOnlyOldFiles) {
  const std::string numbers = "1 -1 2 2 1 1 2 0 0 0\n0.5 1.1 0\n0 90\n0\n10 10\n";
  EXPECT_NEAR(parse_ies("IESNA:LM-63-1995\nTILT=NONE\n" + numbers, "a").intensity(0, 45), 11, 1e-9);
  EXPECT_NEAR(parse_ies("IESNA:LM-63-2002\nTILT=NONE\n" + numbers, "b").intensity(0, 45), 10, 1e-9);
  PhotometricData d = parse_ies("IES:LM-63-2019\nTILT=NONE\n" + numbers, "c");
  EXPECT_EQ(d.format, "IES LM-63-2019");
  EXPECT_NEAR(d.intensity(0, 45), 10, 1e-9);
}

TEST(PhotometricFile, IesErrorsNameTheLine) {
  EXPECT_NE(
      error_of(rotational_ies(90, constant_100)
                   .replace(rotational_ies(90, constant_100).find("TILT=NONE"), 9, "TILT=INCLUDE"))
          .find("lamp.ies:5:1: \"TILT=INCLUDE\": tilt data is not supported"),
      std::string::npos);
  EXPECT_NE(error_of(ies("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10\n")).find("lamp.ies:10"),
            std::string::npos)
      << "a table cut short";
  EXPECT_NE(error_of(ies("1 -1 1 90000 90000 1 2 0 0 0\n1 1 0\n0 90\n0\n10\n"))
                .find("the file ends before its 90000 x 90000 candela values"),
            std::string::npos)
      << "a header that claims a huge table";
  EXPECT_NE(error_of(ies("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 -3\n"))
                .find("lamp.ies:10:4: a candela value must not be negative"),
            std::string::npos);
  EXPECT_NE(error_of(ies("1 -1 1 2 1 2 2 0 0 0\n1 1 0\n0 90\n0\n10 3\n"))
                .find("lamp.ies:6:12: type B photometry is not supported"),
            std::string::npos);
  EXPECT_NE(error_of(ies("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n90 0\n0\n10 3\n"))
                .find("vertical angle must increase"),
            std::string::npos);
  EXPECT_NE(error_of(ies("1 -1 1 2 2 1 2 0 0 0\n1 1 0\n0 90\n0 120\n1 1\n1 1\n"))
                .find("declare no type C symmetry"),
            std::string::npos);
  EXPECT_NE(
      error_of(ies("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 9x\n0\n10 3\n")).find("\"9x\" is not a number"),
      std::string::npos);
  EXPECT_NE(error_of(ies("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 3\n7\n"))
                .find("lamp.ies:11:1: \"7\" after the candela table"),
            std::string::npos);
  EXPECT_NE(error_of("garbage\n").find("no TILT= line"), std::string::npos);
  EXPECT_NE(error_of("").find("empty photometric file"), std::string::npos);
}

// A EULUMDAT file with Mc planes of 90/Mc... degrees, Ng gamma angles 0..180, intensities
// f(C, gamma) in cd/klm for a 2000 lm lamp set.
std::string ldt(int isym, int mc, int ng, double (*f)(double, double)) {
  std::ostringstream s;
  s << "bpm\n1\n"
    << isym << "\n"
    << mc << "\n"
    << 360.0 / mc << "\n"
    << ng << "\n"
    << 180.0 / (ng - 1) << "\nreport\ntest ldt\nno\nfile\ndate\n100\n100\n50\n90\n90\n"
    << "0\n0\n0\n0\n100\n90\n1\n0\n1\n1\nLED\n2000\n3000K\n90\n20\n";
  for (int i = 0; i < 10; ++i) s << "0.5\n";
  for (int i = 0; i < mc; ++i) s << i * 360.0 / mc << "\n";
  for (int j = 0; j < ng; ++j) s << j * 180.0 / (ng - 1) << "\n";
  int mc1 = 1, mc2 = mc;
  if (isym == 1) mc2 = 1;
  if (isym == 2) mc2 = mc / 2 + 1;
  if (isym == 3) mc1 = 3 * mc / 4 + 1, mc2 = mc1 + mc / 2;
  if (isym == 4) mc2 = mc / 4 + 1;
  for (int k = mc1; k <= mc2; ++k)
    for (int j = 0; j < ng; ++j) s << f(((k - 1) % mc) * 360.0 / mc, j * 180.0 / (ng - 1)) << "\n";
  return s.str();
}

double ldt_constant(double, double) { return 50; }
// A function of each symmetry alone (Isym 0: none; 2: about the C 0-180 plane, I(360 - C) =
// I(C); 3: about the C 90-270 plane, I(180 - C) = I(C); 4: both), so that a plane read from the
// wrong place shows.
double deg(double a) { return a * kPi / 180; }
double ldt_none(double c, double g) {
  return (100 + 30 * std::cos(deg(c)) + 20 * std::sin(deg(c))) * (1 + g / 180);
}
double ldt_c0_180(double c, double g) { return (100 + 50 * std::cos(deg(c))) * (1 + g / 180); }
double ldt_c90_270(double c, double g) { return (100 + 50 * std::sin(deg(c))) * (1 + g / 180); }
double ldt_both(double c, double g) { return (100 + 50 * std::cos(deg(2 * c))) * (1 + g / 180); }

TEST(PhotometricFile, EulumdatScalesByTheLampFluxAndUnfolds) {
  PhotometricData d = parse_eulumdat(ldt(1, 36, 19, ldt_constant), "a.ldt");
  EXPECT_EQ(d.format, "EULUMDAT");
  EXPECT_EQ(d.name, "test ldt");
  EXPECT_EQ(d.lamp_lumens, 2000);
  EXPECT_NEAR(d.intensity(123, 77), 100, 1e-9);  // 50 cd/klm of 2000 lm
  EXPECT_NEAR(d.luminous_flux(), 4 * kPi * 100, 1e-6 * 4 * kPi * 100);
  const std::pair<int, double (*)(double, double)> cases[] = {
      {0, ldt_none}, {2, ldt_c0_180}, {3, ldt_c90_270}, {4, ldt_both}};
  for (const auto& [isym, f] : cases) {
    PhotometricData s = parse_eulumdat(ldt(isym, 24, 7, f), "b.ldt");
    for (int k = 0; k < 24; ++k)  // every plane, stored or unfolded; the file holds six digits
      EXPECT_NEAR(s.intensity(15 * k, 60), 2 * f(15 * k, 60), 1e-5 * 2 * f(15 * k, 60))
          << "Isym " << isym << " C " << 15 * k;
  }
  EXPECT_NE(error_of(ldt(4, 22, 7, ldt_both), true).find("cannot have the symmetry"),
            std::string::npos);
  std::string cut = ldt(1, 36, 19, ldt_constant);
  cut.resize(cut.size() - 20);
  EXPECT_NE(error_of(cut, true).find("the file ends before line"), std::string::npos);
  EXPECT_NE(error_of("x\n1\n7\n", true).find("lamp.ldt:3:1: the symmetry indicator Isym"),
            std::string::npos)
      << error_of("x\n1\n7\n", true);
}

// The goniometric image is pbrt-v4's equal-area layout in the luminaire's frame: the centre is
// the zenith (gamma 180), the corners the nadir; equal-area texels make its mean times 4 pi the
// flux.
TEST(PhotometricFile, GoniometricImageHoldsTheTable) {
  PhotometricData d = parse_ies(rotational_ies(90, cosine_1000, 1, 1000), "cos.ies");
  const int n = 256;
  std::vector<float> image = goniometric_image(d, n);
  EXPECT_EQ(image[size_t(n / 2) * n + n / 2], 0.0f);  // straight up: dark
  EXPECT_NEAR(image[0], 1000, 5);                     // a corner: the nadir
  double mean = 0;
  for (float v : image) mean += v;
  mean /= double(image.size());
  EXPECT_NEAR(4 * kPi * mean, d.luminous_flux(), 0.01 * d.luminous_flux());
  const Vec3 up = goniometric_image_direction(Vec2(0.5f, 0.5f));
  EXPECT_NEAR(up.y, 1, 1e-6);
}

}  // namespace
}  // namespace bpm
