// Light sources other than area lights: point, goniometric, projection, spot, distant and
// infinite (uniform or image) lights, with pbrt-v4's "scale", "power" and "illuminance".
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include "lights/photometric_file.h"
#include "scene/flatten_internal.h"
#include "scene/spectra.h"

namespace bpm::flatten_internal {

namespace fs = std::filesystem;

// A light's spectrum; D65 at unit luminance when absent (pbrt-v4's colour-space illuminant).
SpectrumCurve Flattener::light_spectrum(const ParamSet& ps, const std::string& name) {
  return spectrum_curve(ps, name, SpectrumKind::kIlluminant)
      .value_or(SpectrumCurve::from_rgb(Rgb(1.0f), SpectrumKind::kIlluminant));
}

// The image a light's "filename" names (8-bit images decoded as sRGB, as pbrt-v4 does); errors
// name the parameter.
std::shared_ptr<const TexImage> Flattener::light_image(const ParamSet& ps,
                                                       const std::string& light) {
  const Param* f = ps.find_any("filename");
  std::string file = ps.get_string("filename", "");
  if (!f || file.empty())
    throw Error(f ? f->loc : FileLoc{}, light + " light needs \"string filename\"");
  fs::path path =
      fs::path(file).is_absolute() ? fs::path(file) : fs::path(parsed_.base_directory) / file;
  read_data_file(path.string());
  std::shared_ptr<const TexImage> image;
  try {
    image = load_texture_image(path.string(), TexEncoding{});
  } catch (const Error& err) {
    throw Error(f->loc, err.what());
  }
  for (float v : image->texels)
    if (!std::isfinite(v))
      throw Error(f->loc,
                  "\"" + file + "\" has infinite or not-a-number texels and cannot be a light");
  return image;
}

// An environment image light; scale comes in with the light's "scale" and leaves with the
// "illuminance" normalisation applied.
ImageInfiniteLight Flattener::image_light(const LightEntity& e, const Param& file_param,
                                          float* scale) {
  const ParamSet& ps = e.params;
  std::string file = ps.get_string("filename", "");
  ImageInfiniteLight l;
  l.image = light_image(ps, "an infinite");
  const TexImage& im = *l.image;
  if (im.width == im.height) {
    l.equal_area = true;
  } else if (im.width == 2 * im.height) {
    l.equal_area = false;
    warning(file_param.loc,
            "\"" + file + "\" is " + std::to_string(im.width) + "x" + std::to_string(im.height) +
                ": read as a latitude-longitude map (pbrt-v3's layout); pbrt-v4 takes only square "
                "equal-area images");
  } else {
    throw Error(
        file_param.loc,
        "environment image \"" + file + "\" is " + std::to_string(im.width) + "x" +
            std::to_string(im.height) +
            ": it must be square (equal-area) or twice as wide as high (latitude-longitude)");
  }
  if (!e.world_from_light.is_similarity())
    throw Error(e.loc,
                "the transform of an environment light must be a rotation (no non-uniform scale)");
  l.world_from_light = e.world_from_light;
  float E = ps.get_float("illuminance", -1);
  if (E > 0) {
    double e_image = image_light_illuminance(l);
    if (!(e_image > 0))
      throw Error(ps.find_any("illuminance")->loc,
                  "\"illuminance\" is given but the image sends no light to the upper hemisphere");
    *scale *= float(E / e_image);
  }
  l.scale = *scale;
  prepare_image_light(&l);
  return l;
}

// A light source other than an area light. Its "scale" is checked after its kind's "power" or
// "illuminance" has been applied to it.
void Flattener::add_light(const LightEntity& e, RenderScene* rs) {
  const ParamSet& ps = e.params;
  // The medium the light sits in, where light paths start (next-event estimation attenuates by
  // the medium of the point lit and needs none).
  const int medium = e.medium.outside.empty() ? -1 : medium_id(e.medium.outside, e.medium.loc);
  float scale = ps.get_float("scale", 1);
  if (e.name == "point") {
    add_point_light(e, &scale, rs);
  } else if (e.name == "goniometric") {
    add_goniometric_light(e, &scale, rs);
  } else if (e.name == "projection") {
    add_projection_light(e, &scale, rs);
  } else if (e.name == "spot") {
    add_spot_light(e, &scale, rs);
  } else if (e.name == "distant") {
    add_distant_light(e, &scale, rs);
  } else if (e.name == "infinite") {
    add_infinite_light(e, &scale, rs);
  } else {
    throw Error(e.loc, "light \"" + e.name + "\" is not supported");
  }
  if (!(scale >= 0) || !std::isfinite(scale))
    throw Error(e.loc, "light scale must be a non-negative number");
  rs->light_medium.resize(rs->lights.size() - 1, -1);
  rs->light_medium.push_back(medium);
  ps.warn_unused("light \"" + e.name + "\"");
}

void Flattener::add_point_light(const LightEntity& e, float* scale, RenderScene* rs) {
  const ParamSet& ps = e.params;
  const Transform& xf = e.world_from_light;
  SpectrumCurve I = light_spectrum(ps, "I");
  float power = ps.get_float("power", -1);
  if (power > 0) *scale *= power / (4 * kPi);
  rs->lights.push_back(
      PointLight{xf.point(ps.get_point3("from", Vec3(0, 0, 0))), I.scaled(*scale)});
}

void Flattener::add_goniometric_light(const LightEntity& e, float* scale, RenderScene* rs) {
  const ParamSet& ps = e.params;
  const Transform& xf = e.world_from_light;
  if (!ps.find_any("filename"))
    throw Error(e.loc, "goniometric light needs \"string filename\" (its intensity image)");
  GoniometricLight l;
  const std::string file = ps.get_string("filename", "");
  l.image = is_photometric_file(file) ? luminaire_image(ps) : light_image(ps, "goniometric");
  if (l.image->width != l.image->height)
    throw Error(ps.find_any("filename")->loc,
                "goniometric image \"" + ps.get_string("filename", "") + "\" is " +
                    std::to_string(l.image->width) + "x" + std::to_string(l.image->height) +
                    ": it must be square (pbrt-v4's equal-area layout)");
  if (!xf.is_similarity())
    throw Error(e.loc, "the transform of a goniometric light must not scale non-uniformly");
  l.world_from_light = xf;
  prepare_goniometric_light(&l);
  float power = ps.get_float("power", -1);
  if (power > 0) {
    if (!(l.mean_value > 0))
      throw Error(ps.find_any("power")->loc,
                  "\"power\" is given but the goniometric image is black");
    *scale *= power / (4 * kPi * l.mean_value);
  }
  l.intensity = light_spectrum(ps, "I").scaled(*scale);
  rs->lights.push_back(std::move(l));
}

// A bpm extension: a goniometric light whose "filename" is a photometric file (IES LM-63 or
// EULUMDAT) reads it as the image `bpm luminaire` writes for pbrt-v4 (lights/photometric_file.h),
// in candela.
std::shared_ptr<const TexImage> Flattener::luminaire_image(const ParamSet& ps) {
  const std::string file = ps.get_string("filename", "");
  fs::path path =
      fs::path(file).is_absolute() ? fs::path(file) : fs::path(parsed_.base_directory) / file;
  read_data_file(path.string());
  auto image = std::make_shared<TexImage>();
  image->width = image->height = kLuminaireImageSize;
  image->channels = 1;
  image->path = path.string();
  image->texels = goniometric_image(read_photometric_file(path.string()), kLuminaireImageSize);
  return image;
}

void Flattener::add_projection_light(const LightEntity& e, float* scale, RenderScene* rs) {
  const ParamSet& ps = e.params;
  const Transform& xf = e.world_from_light;
  if (!ps.find_any("filename"))
    throw Error(e.loc, "projection light needs \"string filename\" (the projected image)");
  ProjectionLight l;
  l.image = light_image(ps, "projection");
  float fov = ps.get_float("fov", 90);
  if (!(fov > 0 && fov < 180))
    throw Error(ps.find_any("fov")->loc, "projection fov must be in (0, 180) degrees");
  l.tan_half_fov = std::tan(radians(fov) / 2);
  if (!xf.is_similarity())
    throw Error(e.loc, "the transform of a projection light must not scale non-uniformly");
  l.world_from_light = xf;
  l.scale = 1;
  prepare_projection_light(&l);  // power_rgb at scale 1; the distribution does not depend on it
  float power = ps.get_float("power", -1);
  if (power > 0) {
    // pbrt-v4 normalises the luminance-weighted power of the image.
    float phi = l.power_rgb.luminance();
    if (!(phi > 0))
      throw Error(ps.find_any("power")->loc, "\"power\" is given but the projected image is black");
    *scale *= power / phi;
  }
  l.scale = *scale;
  l.power_rgb *= *scale;
  rs->lights.push_back(std::move(l));
}

void Flattener::add_spot_light(const LightEntity& e, float* scale, RenderScene* rs) {
  const ParamSet& ps = e.params;
  const Transform& xf = e.world_from_light;
  SpectrumCurve I = light_spectrum(ps, "I");
  Vec3 from = ps.get_point3("from", Vec3(0, 0, 0)), to = ps.get_point3("to", Vec3(0, 0, 1));
  if (length(to - from) == 0) throw Error(e.loc, "spot light with from == to");
  float cone = ps.get_float("coneangle", 30), delta = ps.get_float("conedeltaangle", 5);
  SpotLight l;
  l.position = xf.point(from);
  l.frame = Frame::from_z(normalize(xf.vector(to - from)));
  l.cos_falloff_end = std::cos(radians(cone));
  l.cos_falloff_start = std::cos(radians(cone - delta));
  float power = ps.get_float("power", -1);
  if (power > 0)
    *scale *= power / (2 * kPi *
                       ((1 - l.cos_falloff_start) + (l.cos_falloff_start - l.cos_falloff_end) / 2));
  l.intensity = I.scaled(*scale);
  rs->lights.push_back(l);
}

void Flattener::add_distant_light(const LightEntity& e, float* scale, RenderScene* rs) {
  const ParamSet& ps = e.params;
  const Transform& xf = e.world_from_light;
  SpectrumCurve L = light_spectrum(ps, "L");
  Vec3 from = ps.get_point3("from", Vec3(0, 0, 0)), to = ps.get_point3("to", Vec3(0, 0, 1));
  if (length(to - from) == 0) throw Error(e.loc, "distant light with from == to");
  float E = ps.get_float("illuminance", -1);
  if (E > 0) *scale *= E;
  rs->lights.push_back(DistantLight{normalize(xf.vector(from - to)), L.scaled(*scale)});
}

namespace {

// pbrt-v4's light portal: four points in world space (not moved by the current transform); the
// light reaches the scene only from the side of cross(p3 - p0, p1 - p0): cross(p1 - p0, p3 - p0)
// points into the scene.
Vec3 portal_normal(const std::vector<Vec3>& p, const FileLoc& loc) {
  if (p.size() != 4) throw Error(loc, "a portal takes 4 points; got " + std::to_string(p.size()));
  const Vec3 n = cross(p[3] - p[0], p[1] - p[0]);
  if (!(length(n) > 0) || !std::isfinite(length(n)))
    throw Error(loc, "the portal's points p0, p1, p3 span no plane");
  return normalize(n);
}

}  // namespace

void Flattener::add_infinite_light(const LightEntity& e, float* scale, RenderScene* rs) {
  const ParamSet& ps = e.params;
  const Param* portal = ps.find_any("portal");
  if (const Param* f = ps.find_any("filename")) {
    if (const Param* l = ps.find_any("L"))
      throw Error(l->loc, "an infinite light takes \"L\" or \"filename\", not both");
    ImageInfiniteLight light = image_light(e, *f, scale);
    if (portal) {
      light.portal_normal = portal_normal(ps.get_point3s("portal"), portal->loc);
      prepare_image_light(&light);  // the texels behind the portal are never drawn
    }
    rs->lights.push_back(std::move(light));
    return;  // add_light checks the scale and the unused parameters
  }
  if (portal)
    throw Error(portal->loc,
                "a portal needs an image infinite light (\"filename\"), as in pbrt-v4");
  SpectrumCurve L = light_spectrum(ps, "L");
  float E = ps.get_float("illuminance", -1);
  if (E > 0) *scale *= E / kPi;
  rs->lights.push_back(UniformInfiniteLight{L.scaled(*scale)});
}

}  // namespace bpm::flatten_internal
