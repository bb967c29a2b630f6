// Camera, film, pixel filter, sampler and integrator settings from the scene file, with
// pbrt-v4's defaults.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scene/flatten_internal.h"

namespace bpm::flatten_internal {

void Flattener::read_camera(LoadedScene* out) {
  scene_ = &out->scene;
  if (!parsed_.camera) {
    out->camera.world_from_camera = Transform();
    return;
  }
  const CameraEntity& c = *parsed_.camera;
  CameraSettings& cam = out->camera;
  // pbrt-v4: the camera sits in the "outside" medium of the MediumInterface in effect.
  cam.medium = medium_id(c.medium.outside, c.medium.loc);
  cam.world_from_camera = c.camera_from_world.inverse();
  if (c.name == "perspective" || c.name == "orthographic") {
    cam.projection = c.name == "perspective" ? Projection::kPerspective : Projection::kOrthographic;
    if (c.name == "perspective") {
      cam.fov_degrees = c.params.get_float("fov", 90);
      if (!(cam.fov_degrees > 0 && cam.fov_degrees < 180))
        throw Error(c.loc, "fov must lie in (0, 180) degrees");
    }
    cam.lens_radius = c.params.get_float("lensradius", 0);
    cam.focal_distance = c.params.get_float("focaldistance", 1e6f);
    if (!(cam.lens_radius >= 0)) throw Error(c.loc, "lensradius must not be negative");
    if (!(cam.focal_distance > 0)) throw Error(c.loc, "focaldistance must be positive");
  } else if (c.name == "spherical") {
    const std::string mapping = c.params.get_string("mapping", "equalarea");
    if (mapping == "equalarea")
      cam.projection = Projection::kSphericalEqualArea;
    else if (mapping == "equirectangular")
      cam.projection = Projection::kSphericalEquirectangular;
    else
      throw Error(
          c.params.find_any("mapping")->loc,
          "spherical camera mapping \"" + mapping + "\" is unknown (equalarea, equirectangular)");
    // pbrt-v4 reads a lens and focus for every camera; a spherical one has no use for them.
    c.params.get_float("lensradius", 0);
    c.params.get_float("focaldistance", 1e30f);
  } else if (c.name == "realistic") {
    cam.projection = Projection::kRealistic;
    read_lens(c);
  } else {
    throw Error(c.loc, "camera \"" + c.name +
                           "\" is unknown (perspective, orthographic, spherical, realistic)");
  }
  cam.frame_aspect_ratio = c.params.get_float("frameaspectratio", 0);
  if (c.params.find_any("frameaspectratio") && !(cam.frame_aspect_ratio > 0))
    throw Error(c.params.find_any("frameaspectratio")->loc, "frameaspectratio must be positive");
  auto sw = c.params.get_floats("screenwindow");
  if (!sw.empty()) {
    if (sw.size() != 4)
      throw Error(c.params.find_any("screenwindow")->loc, "screenwindow needs 4 values");
    if (!(sw[0] != sw[1] && sw[2] != sw[3]))
      throw Error(c.params.find_any("screenwindow")->loc, "screenwindow is empty");
    for (int i = 0; i < 4; ++i) cam.screen_window[i] = sw[size_t(i)];
  }
  float open = c.params.get_float("shutteropen", 0), close = c.params.get_float("shutterclose", 1);
  if (close < open) throw Error(c.loc, "shutterclose is before shutteropen");
  out->film.imaging_ratio = close - open;
  c.params.warn_unused("camera");
}

namespace {

// pbrt-v4's "cropwindow" (x0 x1 y0 y1 in [0, 1], clamped, either order) or "pixelbounds" (x0 x1 y0
// y1 in pixels of the file's resolution), not both: the image is the crop of the camera's raster.
void read_crop(const ParamSet& ps, FilmSettings* film) {
  const Param* cw = ps.find_any("cropwindow");
  const Param* pb = ps.find_any("pixelbounds");
  if (cw && pb)
    throw Error(pb->loc, "both \"cropwindow\" and \"pixelbounds\" were given; only one may be");
  film->file_width = film->width;
  film->file_height = film->height;
  if (cw) {
    const std::vector<float> c = ps.get_floats("cropwindow");
    if (c.size() != 4)
      throw Error(cw->loc,
                  "cropwindow takes 4 values (x0 x1 y0 y1); got " + std::to_string(c.size()));
    for (float v : c)
      if (!std::isfinite(v)) throw Error(cw->loc, "cropwindow values must be finite");
    film->crop_window[0] = std::clamp(std::min(c[0], c[1]), 0.0f, 1.0f);
    film->crop_window[1] = std::clamp(std::max(c[0], c[1]), 0.0f, 1.0f);
    film->crop_window[2] = std::clamp(std::min(c[2], c[3]), 0.0f, 1.0f);
    film->crop_window[3] = std::clamp(std::max(c[2], c[3]), 0.0f, 1.0f);
  }
  if (pb) {
    const std::vector<int> b = ps.get_ints("pixelbounds");
    if (b.size() != 4)
      throw Error(pb->loc,
                  "pixelbounds takes 4 values (x0 x1 y0 y1); got " + std::to_string(b.size()));
    if (b[1] <= b[0] || b[3] <= b[2])
      throw Error(pb->loc, "pixelbounds [" + std::to_string(b[0]) + " " + std::to_string(b[1]) +
                               " " + std::to_string(b[2]) + " " + std::to_string(b[3]) +
                               "] is empty");
    for (int k = 0; k < 4; ++k) film->pixel_bounds[k] = b[size_t(k)];
    film->has_pixel_bounds = true;
  }
  film->set_full_resolution(film->width, film->height);
  if (film->width <= 0 || film->height <= 0)
    throw Error((cw ? cw : pb)->loc, std::string(cw ? "cropwindow" : "pixelbounds") +
                                         " leaves no pixel of the " +
                                         std::to_string(film->full_width) + "x" +
                                         std::to_string(film->full_height) + " image");
}

}  // namespace

namespace {

// pbrt-v4's spectral film: its buckets, and an EXR file (the only format it writes).
void read_spectral_film(const SceneEntity& f, SpectralBuckets* b) {
  b->count = f.params.get_int("nbuckets", 16);
  if (b->count < 1 || b->count > 1000)
    throw Error(f.params.find_any("nbuckets")->loc, "nbuckets must be in [1, 1000]");
  b->lambda_min = f.params.get_float("lambdamin", kLambdaMin);
  b->lambda_max = f.params.get_float("lambdamax", kLambdaMax);
  if (!(b->lambda_min >= kLambdaMin && b->lambda_max <= kLambdaMax &&
        b->lambda_min < b->lambda_max))
    throw Error(f.loc, "lambdamin and lambdamax must lie in [360, 830] nm, lambdamin below");
  const std::string name = f.params.get_string("filename", "pbrt.exr");
  if (!name.ends_with(".exr"))
    throw Error(f.params.find_any("filename")->loc,
                "a spectral film writes EXR only; \"" + name + "\" is not an .exr file");
}

}  // namespace

void Flattener::read_film(LoadedScene* out) {
  const SceneEntity& f = parsed_.film;
  if (f.name != "rgb" && f.name != "spectral")
    throw Error(f.loc, "film \"" + f.name + "\" is not supported (rgb, spectral)");
  if (f.name == "spectral") read_spectral_film(f, &out->film.spectral);
  out->film.width = f.params.get_int("xresolution", 1280);
  out->film.height = f.params.get_int("yresolution", 720);
  if (out->film.width <= 0 || out->film.height <= 0 || out->film.width > 65536 ||
      out->film.height > 65536)
    throw Error(f.loc, "film resolution must be between 1 and 65536 pixels per axis");
  out->film.filename = f.params.get_string("filename", "pbrt.exr");
  // The film's size in mm: only the realistic camera uses it (read with the lens).
  if (!(f.params.get_float("diagonal", 35) > 0))
    throw Error(f.params.find_any("diagonal")->loc, "diagonal must be positive");
  float iso = f.params.get_float("iso", 100);
  if (!(iso > 0)) throw Error(f.loc, "iso must be positive");
  out->film.imaging_ratio *= iso / 100;
  out->film.sensor = f.params.get_string("sensor", "cie1931");
  if (out->film.sensor != "cie1931") {
    const std::vector<std::string> names = CameraResponse::names();
    if (std::find(names.begin(), names.end(), out->film.sensor) == names.end()) {
      std::string list = "cie1931";
      for (const std::string& n : names) list += ", " + n;
      throw Error(f.params.find_any("sensor")->loc,
                  "sensor \"" + out->film.sensor + "\" is unknown (" + list + ")");
    }
  }
  out->film.white_balance = f.params.get_float("whitebalance", 0);
  if (!(out->film.white_balance >= 0) || !std::isfinite(out->film.white_balance) ||
      (out->film.white_balance > 0 && out->film.white_balance < 1000))
    throw Error(f.params.find_any("whitebalance")->loc,
                "whitebalance must be 0 (none) or a temperature of at least 1000 K");
  out->film.max_component_value = f.params.get_float("maxcomponentvalue", kInf);
  read_crop(f.params, &out->film);
  f.params.get_bool("savefp16", true);  // bpm always writes 32-bit float EXR
  f.params.warn_unused("film");
}

void Flattener::read_filter(LoadedScene* out) {
  const SceneEntity& f = parsed_.filter;
  FilterSettings& s = out->filter;
  float def = 0.5f;
  if (f.name == "box")
    s.type = FilterType::kBox, def = 0.5f;
  else if (f.name == "triangle")
    s.type = FilterType::kTriangle, def = 2;
  else if (f.name == "gaussian")
    s.type = FilterType::kGaussian, def = 1.5f;
  else if (f.name == "mitchell")
    s.type = FilterType::kMitchell, def = 2;
  else if (f.name == "sinc")
    s.type = FilterType::kLanczos, def = 4;
  else
    throw Error(f.loc, "pixel filter \"" + f.name + "\" is unknown");
  s.radius = {f.params.get_float("xradius", def), f.params.get_float("yradius", def)};
  if (!(s.radius.x > 0 && s.radius.y > 0)) throw Error(f.loc, "filter radius must be positive");
  s.sigma = f.params.get_float("sigma", 0.5f);
  s.b = f.params.get_float("B", 1.0f / 3);
  s.c = f.params.get_float("C", 1.0f / 3);
  s.tau = f.params.get_float("tau", 3);
  f.params.warn_unused("pixel filter");
}

void Flattener::read_sampler_and_integrator(LoadedScene* out) {
  const SceneEntity& s = parsed_.sampler;
  static const char* samplers[] = {"zsobol",      "sobol",   "paddedsobol", "halton",
                                   "independent", "pmj02bn", "stratified"};
  bool known = false;
  for (const char* n : samplers) known = known || s.name == n;
  if (!known) throw Error(s.loc, "sampler \"" + s.name + "\" is unknown");
  out->render.spp = s.params.get_int("pixelsamples", 16);
  if (s.name == "stratified")
    out->render.spp = s.params.get_int("xsamples", 4) * s.params.get_int("ysamples", 4);
  if (out->render.spp <= 0) throw Error(s.loc, "pixelsamples must be positive");
  out->render.seed = s.params.get_int("seed", 0);
  s.params.get_bool("jitter", true);
  s.params.get_string("randomization", "");
  s.params.warn_unused("sampler");

  const SceneEntity& in = parsed_.integrator;
  out->render.integrator_as_written = in.name;
  out->render.max_depth = in.params.get_int("maxdepth", 5);
  if (out->render.max_depth < 0) throw Error(in.loc, "maxdepth must not be negative");
  // pbrt-v4's integrators map to the one of ours that reaches the same light: the path tracers to
  // path; those that also carry light from the lights' side (bidirectional, Metropolis, light
  // tracing, photon mapping) to bpm, for a path tracer cannot reach a point or spot light through
  // glass and would silently drop such caustics. All of them estimate the same image.
  const std::string& n = in.name;
  std::string& note = out->render.integrator_note;
  if (n == "path" || n == "bpm" || n == "fpm") {
    out->render.integrator = n;
  } else if (n == "volpath" || n == "simplepath" || n == "simplevolpath" || n == "randomwalk") {
    out->render.integrator = "path";
    // volpath is also pbrt-v4's default when the file names none.
    if (parsed_.integrator_given)
      note = "integrator \"" + n + "\" is rendered with bpm's path tracer (\"path\"), as " + n +
             " is one";
  } else if (n == "bdpt" || n == "mlt" || n == "lightpath") {
    out->render.integrator = "bpm";
    note = "integrator \"" + n +
           "\" is rendered with backward photon mapping (\"bpm\"), which like " + n +
           " also reaches light a path tracer cannot (caustics of small and point lights)";
  } else if (n == "sppm") {
    out->render.integrator = "bpm";
    note =
        "integrator \"sppm\" is rendered with backward photon mapping (\"bpm\") at diffuse "
        "depth 0, the photon method closest to sppm" +
        std::string(in.params.find_any("radius") ? ", from its initial radius" : "");
  } else {
    throw Error(in.loc, "integrator \"" + n + "\" is not supported");
  }
  for (const Param& p : in.params.all()) p.used = true;  // other integrators' knobs are advisory
  out->render.integrator_directive = in;
}

}  // namespace bpm::flatten_internal
