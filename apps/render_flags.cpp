#include "render_flags.h"

#include <cmath>
#include <cstdlib>

namespace bpm {
namespace {

// CLI11's Range lets NaN through (every comparison with it is false), so the floats are checked to
// be finite first. (A word that is no number at all is left to Range, which says so.)
const CLI::Validator kFinite(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      return end != text.c_str() && !std::isfinite(v) ? "must be a finite number" : "";
    },
    "", "finite");

// The flags of `bpm render`, in the manual's groups (docs/USAGE.md).
const char* const kGeneral = "General";
const char* const kBudgets = "Budgets (the first one reached ends the render)";
const char* const kOutputs = "Outputs, checkpoints and the error estimate";
const char* const kBpm =
    "Backward photon mapping (--integrator bpm; the photon flags also apply to fpm)";
const char* const kFpm = "Forward photon mapping (--integrator fpm)";

void add_general_options(CLI::App* render, RenderRequest& ra) {
  render->add_option("scene", ra.scene, "Scene file (.pbrt)")->required();
  render
      ->add_option("--integrator", ra.integrator,
                   "Integrator: path, bpm or fpm; default: the scene file's")
      ->check(CLI::IsMember({"path", "bpm", "fpm"}))
      ->group(kGeneral);
  render->add_option("--resolution", ra.resolution, "Image size WxH; default: the scene file's")
      ->group(kGeneral);
  render->add_option("--threads", ra.threads, "Worker threads; default: all cores")
      ->check(CLI::Range(1, 4096))
      ->group(kGeneral);
  render
      ->add_option("--seed", ra.seed,
                   "Random seed; default: the sampler's seed in the file, else 0")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 62))
      ->group(kGeneral);
  render
      ->add_option("--maxdepth", ra.max_depth,
                   "Maximum scattering events; default: the file's maxdepth (5)")
      ->check(CLI::Range(0, 100000))
      ->group(kGeneral);
  render
      ->add_flag("--no-equiangular", ra.no_equiangular,
                 "Direct light in scattering media from free-flight points only, "
                 "without equiangular sampling along the camera's rays")
      ->group(kGeneral);
  render->add_flag("-q,--quiet", ra.quiet, "No progress output")->group(kGeneral);
}

void add_budget_options(CLI::App* render, RenderRequest& ra) {
  render->add_option("--spp", ra.spp, "Samples per pixel; default: the scene file's pixelsamples")
      ->check(CLI::Range(1, 1 << 24))
      ->group(kBudgets);
  render
      ->add_option("--iterations", ra.iterations,
                   "Iterations (each one eye sample per pixel and a photon pass); same as --spp")
      ->check(CLI::Range(1, 1 << 24))
      ->group(kBudgets);
  render
      ->add_option("--time", ra.time,
                   "Time budget in seconds (stops after the pass that exceeds it)")
      ->check(kFinite)
      ->check(CLI::Range(0.0, 1e9))
      ->group(kBudgets);
  render
      ->add_option(
          "--accuracy", ra.accuracy,
          "Stop when the image error delta (eq. 4 of the paper) is at most this, e.g. 0.01")
      ->check(kFinite)
      ->check(CLI::Range(1e-6, 1.0))
      ->group(kBudgets);
  render
      ->add_option("--memory", ra.memory,
                   "Memory budget for the render's data (film, photon maps, trees, photon "
                   "entries), e.g. 512M or 8G; default: 3/4 of this machine's memory")
      ->group(kBudgets);
  render
      ->add_flag("--no-adaptive", ra.no_adaptive,
                 "Sample every pixel in every pass (by default pixels with a larger relative "
                 "error get more passes)")
      ->group(kBudgets);
  render
      ->add_option(
          "--adaptive-floor", ra.adaptive_floor,
          "Lowest probability of sampling a pixel in a pass under adaptive sampling (default 0.1)")
      ->check(kFinite)
      ->check(CLI::Range(0.01, 1.0))
      ->group(kBudgets);
}

void add_output_options(CLI::App* render, RenderRequest& ra) {
  render
      ->add_option("-o,--output", ra.output,
                   "Output EXR; PNG, .error.png and .json are written beside it")
      ->group(kOutputs);
  render
      ->add_option("--write-every", ra.write_every,
                   "Write the outputs so far, and OUT.checkpoint to resume from, every SECONDS "
                   "(atomically)")
      ->check(kFinite)
      ->check(CLI::Range(0.1, 1e9))
      ->group(kOutputs);
  render
      ->add_option("--resume", ra.resume,
                   "Go on from a checkpoint (OUT.checkpoint of --write-every) of the same "
                   "render: the same scene, resolution, integrator and settings; --spp and "
                   "--iterations count the passes before it too")
      ->group(kOutputs);
  render
      ->add_option("--sensors", ra.sensors,
                   "Illuminance sensors, one a line (x y z nx ny nz, as Radiance's rtrace -I) or a "
                   "grid (grid x y z ux uy uz vx vy vz nu nv); writes OUT.sensors.csv in lux")
      ->check(CLI::ExistingFile)
      ->group(kOutputs);
  render
      ->add_flag("--no-image", ra.no_image,
                 "Render the sensors alone: no image, no EXR or PNG (needs --sensors)")
      ->group(kOutputs);
  render
      ->add_option("--m-images", ra.m_images,
                   "Keep M intermediate images (pass j to image j mod M): the photon methods' "
                   "error estimate (2, 4 or 8), a second one for path (0: off; default 8)")
      ->check(CLI::Range(0, 64))
      ->group(kOutputs);
}

// The photon flags both photon methods read (PhotonSettings), then bpm's own.
void add_photon_options(CLI::App* render, RenderRequest& ra) {
  render->add_option("--k0", ra.k0, "Caustic radius in pixel footprints (default 1)")
      ->check(kFinite)
      ->check(CLI::Range(1e-4, 1e4))
      ->group(kBpm);
  render
      ->add_option("--k1", ra.k1,
                   "Radius at the last diffuse vertex in pixel footprints (default 4.5)")
      ->check(kFinite)
      ->check(CLI::Range(1e-4, 1e4))
      ->group(kBpm);
  render
      ->add_option("--radius-policy", ra.radius_policy,
                   "fixed, progressive (fpm's default) or perpixel (bpm's default)")
      ->check(CLI::IsMember({"fixed", "progressive", "perpixel"}))
      ->group(kBpm);
  render
      ->add_option("--alpha", ra.alpha,
                   "Progressive radius alpha: r2 *= (i+alpha)/(i+1) (default 2/3)")
      ->check(kFinite)
      ->check(CLI::Range(1e-3, 0.999))
      ->group(kBpm);
  render
      ->add_option("--photons", ra.photons,
                   "Photons per iteration, fixed (bpm's default: chosen each round from the "
                   "variances and costs of the eye and light passes, starting from and never "
                   "above 100000 per 256x256 pixels, at least 100000; fpm's default: that count, "
                   "no more than --memory holds; file: integer photonsperiteration)")
      ->check(CLI::Range(1, 1 << 30))
      ->group(kBpm);
  render
      ->add_flag("--no-disc-probes", ra.no_disc_probes,
                 "bpm and fpm: divide the photons an estimate gathers by its whole disc, even "
                 "where a wall or an edge leaves photons part of it (file: bool discprobes false)")
      ->group(kBpm);
  render
      ->add_flag("--split-in-media", ra.split_in_media,
                 "bpm: an eye ray through a scattering medium gathers on every piece it crosses "
                 "and also goes on past it, instead of where a free flight makes it scatter "
                 "(file: bool splitinmedia true)")
      ->group(kBpm);
  render
      ->add_flag("--debias", ra.debias,
                 "bpm and fpm: record the image less its bias estimate (2 L(r/sqrt 2) - L(r) "
                 "under --bias-model r2); noisier, and without a bias estimate of its own")
      ->group(kBpm);
  render
      ->add_option("--bias-model", ra.bias_model,
                   "bpm and fpm: how the radius bias is estimated: r2 (two radii, the leading r^2 "
                   "term of a smooth density; default) or r2+r (three radii, also the r term of "
                   "edges)")
      ->check(CLI::IsMember({"r2", "r2+r"}))
      ->group(kBpm);
}

void add_bpm_options(CLI::App* render, RenderRequest& ra) {
  render
      ->add_option("--diffuse-depth", ra.diffuse_depth,
                   "Diffuse vertices before the last backward photon (0..3; default 0)")
      ->check(CLI::Range(0, 3))
      ->group(kBpm);
  add_photon_options(render, ra);
  render
      ->add_flag(
          "--no-guide", ra.no_guide,
          "Emit photons in proportion to light power only, without learning where the camera "
          "sees them (file: bool guideemission false)")
      ->group(kBpm);
  render
      ->add_option("--radius", ra.radius,
                   "Initial radius of every backward photon in scene units, in place of --k0 and "
                   "--k1 (default 0: off; file: float radius, also pbrt-v4 sppm's)")
      ->check(kFinite)
      ->check(CLI::Range(0.0, 1e30))
      ->group(kBpm);
  render
      ->add_option("--emission-samples", ra.emission_samples,
                   "Most camera samples per iteration for light seen directly or through specular "
                   "surfaces, in pixels that show any; each pixel takes what its measured "
                   "variance pays for (default 8; file: integer emissionsamples)")
      ->check(CLI::Range(1, 1024))
      ->group(kBpm);
  render
      ->add_option("--direct-samples", ra.direct_samples,
                   "Most samples of direct light per iteration at an eye path's last diffuse "
                   "vertex; each pixel takes what its measured variance pays for (default 8; "
                   "file: integer directsamples)")
      ->check(CLI::Range(1, 1024))
      ->group(kBpm);
  render
      ->add_option("--estimators", ra.estimators,
                   "partition: indirect light at the last diffuse vertex comes from the photons "
                   "alone; combined: the eye path also goes on from there, and each light path is "
                   "weighed between the photons and the continuation by multiple importance "
                   "sampling; glossy: combined where that vertex's gathered lobes include a glossy "
                   "one, partition elsewhere; auto (default): as glossy, and elsewhere combined "
                   "with a probability each pixel chooses from its own variance and cost (paths "
                   "through scattering media stay the photons'; file: string estimators)")
      ->check(CLI::IsMember({"partition", "glossy", "combined", "auto"}))
      ->group(kBpm);
  render
      ->add_option("--camera-connections", ra.camera_connections,
                   "on (default): caustic photons that land where the camera sees them are also "
                   "joined to the camera, and each such light path is weighed between that and the "
                   "merge at the pixels' first vertices by multiple importance sampling; off: the "
                   "merges alone; alone: the connections alone, a check (pinhole perspective "
                   "cameras, scenes without media; file: string cameraconnections)")
      ->check(CLI::IsMember({"on", "off", "alone"}))
      ->group(kBpm);
  render
      ->add_option("--vertex-connections", ra.vertex_connections,
                   "on: each photon's vertex on a surface with gathered lobes is also joined by a "
                   "shadow ray to the last diffuse vertex of a pixel's eye path drawn at random, "
                   "and each such light path is weighed between that, the merge and the eye "
                   "path's continuation by multiple importance sampling; off (default): not; "
                   "alone: the connections take the merges' share, a check (scenes without media; "
                   "file: string vertexconnections)")
      ->check(CLI::IsMember({"on", "off", "alone"}))
      ->group(kBpm);
  render
      ->add_flag("--no-coat-split", ra.no_coat_split,
                 "At a coated surface where gathering would end the eye path, take its coat or "
                 "its base by chance instead of both (file: bool splitcoats false)")
      ->group(kBpm);
  render->add_option("--tree", ra.tree, "Backward photon kd-tree: spheres (default) or centres")
      ->check(CLI::IsMember({"spheres", "centres"}))
      ->group(kBpm);
}

void add_fpm_options(CLI::App* render, RenderRequest& ra) {
  render
      ->add_flag("--final-gather", ra.final_gather,
                 "Read indirect light one diffuse bounce after the first hit")
      ->group(kFpm);
  render
      ->add_option("--knn", ra.knn,
                   "Radius from the N nearest photons, capped by the k1 radius (0: off)")
      ->check(CLI::Range(0, 100000))
      ->group(kFpm);
}

}  // namespace

CLI::App* add_render_command(CLI::App& app, RenderRequest& ra) {
  CLI::App* render = app.add_subcommand(
      "render", "Render a pbrt-v4 scene to EXR, PNGs (image, luminance, error) and JSON");
  add_general_options(render, ra);
  add_budget_options(render, ra);
  add_output_options(render, ra);
  add_bpm_options(render, ra);
  add_fpm_options(render, ra);
  return render;
}

RenderRequest parse_render_request(const std::vector<std::string>& args) {
  CLI::App app;
  RenderRequest request;
  CLI::App* render = add_render_command(app, request);
  render->allow_extras(false);
  // CLI11 takes the arguments last first.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  reversed.push_back("render");
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    throw Error(e.what());
  }
  return request;
}

}  // namespace bpm
