// bpm: command-line front end. `bpm render SCENE.pbrt` renders a pbrt-v4 scene; `bpm compare A.exr
// B.exr` prints how two renders differ; `bpm luminaire FILE.ies` writes a luminaire for pbrt-v4.
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "base/error.h"
#include "base/memory.h"
#include "film/image_compare.h"
#include "film/image_io.h"
#include "film/outputs.h"
#include "integrator/control.h"
#include "integrator/team.h"
#include "lights/photometric_file.h"
#include "path/sensors.h"
#include "render/checkpoint.h"
#include "render_flags.h"
#ifdef BPM_HAVE_MPI
#include "render/mpi_team.h"
#endif
#include "render/render_job.h"
#include "render/renderer.h"
#include "scene/flatten.h"
#include "scene/parsed_scene.h"

namespace {

using namespace bpm;

// The bpm statistics a user wants to see at the end of a run (all of them are in the JSON).
void print_bpm_summary(const nlohmann::json& d) {
  const auto &eye = d["eye"], &light = d["light"], &maps = d["maps"], &st = d["stages_s"];
  std::fprintf(
      stderr,
      "bpm: eye: %.3g rays, %.3g backward photons (%.3f per eye path), %.2f Mrays/s\n"
      "bpm: maps: %.1f MB photons, %.1f MB trees (peak), build %.2f s, sphere duplication %.2f\n"
      "bpm: light: %.3g photons, %.3g rays, %.2f Mrays/s, %.3g queries (%.2f M/s), %.1f "
      "batches/iteration, "
      "%.2f of the last backward photons hit\n"
      "bpm: stages: eye %.2f s, trees %.2f s, light trace %.2f + gather %.2f + apply %.2f s, "
      "disc probes %.2f s, accumulate %.2f s\n",
      double(eye["camera_rays"].get<uint64_t>() + eye["bounce_rays"].get<uint64_t>() +
             eye["shadow_rays"].get<uint64_t>()),
      double(eye["backward_photons"].get<uint64_t>()),
      eye["backward_photons_per_backward_ray"].get<double>(),
      eye["rays_per_second"].get<double>() * 1e-6, maps["peak_photon_bytes"].get<double>() * 1e-6,
      maps["peak_tree_bytes"].get<double>() * 1e-6, maps["tree_build_s"].get<double>(),
      maps["mean_sphere_duplication"].get<double>(), double(light["photons"].get<uint64_t>()),
      double(light["light_rays"].get<uint64_t>()), light["rays_per_second"].get<double>() * 1e-6,
      double(light["queries"].get<uint64_t>()), light["queries_per_second"].get<double>() * 1e-6,
      light["batches_per_iteration"].get<double>(), light["coverage_mean"].get<double>(),
      st["eye"].get<double>(), st["tree_build"].get<double>(), st["light_trace"].get<double>(),
      st["light_gather"].get<double>(), st["light_apply"].get<double>(),
      st["disc_probes"].get<double>(), st["accumulate"].get<double>());
}

void print_fpm_summary(const nlohmann::json& d) {
  const auto &light = d["light"], &maps = d["maps"], &st = d["stages_s"];
  std::fprintf(
      stderr,
      "bpm: fpm light: %.3g photons, %.3g rays, %.3g photons stored (%.3f per photon path, a "
      "forward ray), %.2f Mrays/s\n"
      "bpm: fpm maps: %.1f MB photons, %.1f MB trees (peak), build %.2f s\n"
      "bpm: fpm stages: light %.2f s, trees %.2f s, eye %.2f s\n",
      double(light["photons"].get<uint64_t>()), double(light["light_rays"].get<uint64_t>()),
      double(light["photons_stored"].get<uint64_t>()),
      light["photons_per_forward_ray"].get<double>(), light["rays_per_second"].get<double>() * 1e-6,
      maps["peak_photon_bytes"].get<double>() * 1e-6, maps["peak_tree_bytes"].get<double>() * 1e-6,
      maps["tree_build_s"].get<double>(), st["light"].get<double>(), st["tree_build"].get<double>(),
      st["eye"].get<double>());
}

// --resume: the checkpoint, checked against this render; the film's sums are process 0's alone
// (the others' films hold their passes until a round ends); every process takes the render state.
void resume_from(const RenderRequest& a, const nlohmann::json& identity, bool root,
                 Checkpoint* resumed, Film* film, RenderOptions* opt) {
  *resumed = read_checkpoint(a.resume);
  check_identity(resumed->identity, identity, a.resume);
  ByteReader r(resumed->film, "checkpoint \"" + a.resume + "\"");
  if (root) film->load(r);
  std::vector<uint8_t>().swap(resumed->film);
  opt->resume = &resumed->state;
  if (!a.quiet)
    std::fprintf(stderr, "bpm: resuming %s after %d %s\n", a.resume.c_str(), resumed->state.passes,
                 opt->integrator == "path" ? "passes" : "iterations");
}

// What a finished render prints on stderr.
void print_result(const RenderRequest& a, const RenderOptions& opt, const RenderStats& st,
                  const Film& film, const OutputPaths& paths) {
  if (film.dropped_samples() > 0)
    std::fprintf(stderr,
                 "bpm: warning: %llu samples had a non-finite or negative value (a numerical "
                 "accident) and were recorded as black (result.dropped_samples in the JSON)\n",
                 (unsigned long long)film.dropped_samples());
  if (a.quiet) return;
  if (opt.integrator == "bpm") print_bpm_summary(st.details);
  if (opt.integrator == "fpm") print_fpm_summary(st.details);
  char bias[64] = "";
  if (film.has_bias())
    std::snprintf(bias, sizeof bias, " (noise %.4f, bias %.4f)", st.relative_error,
                  film.relative_error_bias());
  char sensors[48] = "";
  if (film.sensor_count() > 0)
    std::snprintf(sensors, sizeof sensors, ", sensors' delta %.4f", film.sensor_relative_error());
  std::fprintf(stderr, "bpm: %d %s in %.2f s (%s), %.2f Mrays/s, delta %.4f%s%s -> %s\n", st.passes,
               opt.integrator == "path" ? "spp" : "iterations", st.render_seconds,
               st.stop_reason.c_str(),
               st.render_seconds > 0 ? st.total_rays() / st.render_seconds * 1e-6 : 0.0,
               film.relative_error_total(), bias, sensors,
               opt.image ? paths.exr.c_str() : paths.sensors.c_str());
}

// With several processes (mpirun), process 0 alone prints and writes; the others render.
int run_render(RenderRequest a, Team* team, bool* rendering) {
  const bool root = !team || team->rank() == 0;
  if (!root) a.quiet = true;
  const SceneFile file = read_scene_file(a.scene);
  auto t = Clock::now();
  const LoadedScene ls = build_scene(file, a);
  const double build_s = since(t);
  RenderOptions opt = render_options(a, ls, file.settings);
  const OutputPaths paths = checked_output_paths(a, ls.film);
  if (!a.quiet)
    std::fprintf(stderr, "bpm: %s: %zu objects, %zu triangles, %zu lights, %dx%d, integrator %s\n",
                 a.scene.c_str(), ls.scene.objects.size(), ls.scene.triangle_count(),
                 ls.scene.lights.size(), ls.film.width, ls.film.height, opt.integrator.c_str());
  // A checkpoint is kept when outputs are written as the render goes, or when it resumes one
  // (so that it can be resumed again); it is written every --write-every and at the end.
  // (Only then: its fingerprint reads every scene and data file again.)
  const bool keep_checkpoint = opt.write_every_s > 0 || !a.resume.empty();
  check_film_memory(a, ls, opt, keep_checkpoint, team != nullptr);
  Film film(ls.film.width, ls.film.height, a.m_images, opt.sensors.size());
  film.set_spectral(ls.film.spectral);
  std::vector<std::string> files = file.parsed.files;
  if (!a.sensors.empty()) files.push_back(a.sensors);  // a checkpoint holds these sensors' sums
  const nlohmann::json identity =
      keep_checkpoint ? render_identity(files, ls, opt, film.m_images()) : nlohmann::json();
  Checkpoint resumed;
  if (!a.resume.empty()) resume_from(a, identity, root, &resumed, &film, &opt);
  if (keep_checkpoint && root)
    opt.save_state = [&](const RenderState& state) {
      const std::vector<uint8_t> bytes = encode_checkpoint(identity, film, state);
      write_bytes_atomic(paths.checkpoint, bytes.data(), bytes.size());
    };
  install_interrupt_handlers();
  if (root)
    opt.checkpoint = [&](int passes) { write_intermediate(a, ls, opt, film, paths, passes); };
  opt.team = team;
  *rendering = true;
  RenderStats st = render(ls, opt, &film);
  if (!root) return 0;

  t = Clock::now();
  write_outputs(ls.film, opt, film, paths);
  const double write_s = since(t);
  nlohmann::json rec = run_record(a, ls, opt, st, film, paths, {file.parse_s, build_s, write_s});
  write_text_atomic(paths.json, rec.dump(2) + "\n");
  print_result(a, opt, st, film, paths);
  return st.stop_reason == "interrupted" ? 130 : 0;
}

int run_compare(const std::string& a_path, const std::string& b_path) {
  Image a = read_exr(a_path), b = read_exr(b_path);
  if (a.width != b.width || a.height != b.height)
    throw Error("images differ in size: " + std::to_string(a.width) + "x" +
                std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                std::to_string(b.height));
  ImageComparison c = compare_images(a, b);
  const auto &ma = c.mean_a, &mb = c.mean_b;
  std::printf("mean A      %.6f %.6f %.6f\n", ma[0], ma[1], ma[2]);
  std::printf("mean B      %.6f %.6f %.6f\n", mb[0], mb[1], mb[2]);
  std::printf("mean A/B-1  %+.4f %+.4f %+.4f\n", ma[0] / mb[0] - 1, ma[1] / mb[1] - 1,
              ma[2] / mb[2] - 1);
  std::printf("relMSE      %.6f   (mean over pixels and channels of (a-b)^2/(b^2+0.01))\n",
              c.rel_mse);
  return 0;
}

// `bpm luminaire FILE`: the image and the LightSource lines with which pbrt-v4 renders the
// luminaire of a photometric file (lights/photometric_file.h), as bpm does when a goniometric
// light names the file itself.
struct LuminaireArgs {
  std::string file, output;
  int size = kLuminaireImageSize;
};

int run_luminaire(const LuminaireArgs& a) {
  const PhotometricData d = read_photometric_file(a.file);
  std::string out = a.output;
  if (out.empty()) out = std::filesystem::path(a.file).stem().string() + ".exr";
  if (std::filesystem::path(out).extension() != ".exr")
    throw Error("luminaire image \"" + out + "\" must end in .exr");
  Image img;
  img.width = img.height = a.size;
  for (float v : goniometric_image(d, a.size)) img.rgb.insert(img.rgb.end(), {v, v, v});
  write_exr(out, img);
  std::printf(
      "# %s%s%s (%s): %.6g lm, the integral of its intensities; lamps %.6g lm%s\n"
      "# The image holds candela toward each direction of pbrt-v4's goniometric light: the\n"
      "# luminaire's nadir (gamma 0) along the light's -y, C 0 along +x and C 90 along +z, so\n"
      "# that C runs counterclockwise seen from above in pbrt-v4's left-handed coordinates.\n"
      "AttributeBegin\n"
      "  Translate 0 0 0    # where the luminaire is\n"
      "  Rotate 90 1 0 0    # in a scene whose up is +z (nadir along -z, C 90 along -y); leave it\n"
      "                     # out where up is +y\n"
      "  LightSource \"goniometric\" \"string filename\" \"%s\"\n"
      "AttributeEnd\n",
      a.file.c_str(), d.name.empty() ? "" : ", ", d.name.c_str(), d.format.c_str(),
      d.luminous_flux(), d.lamp_lumens, d.lamp_lumens > 0 ? "" : " (absolute photometry)",
      out.c_str());
  return 0;
}

void add_luminaire_command(CLI::App& app, LuminaireArgs& la) {
  CLI::App* luminaire = app.add_subcommand(
      "luminaire",
      "Write the goniometric image of an IES or EULUMDAT file for pbrt-v4, and print the "
      "LightSource lines that place it");
  luminaire->add_option("file", la.file, "Photometric file (.ies or .ldt)")
      ->required()
      ->check(CLI::ExistingFile);
  luminaire->add_option("-o,--output", la.output,
                        "The image (EXR); default: the file's name with .exr, in this folder");
  luminaire
      ->add_option("--size", la.size,
                   "Side of the square image in texels (default " +
                       std::to_string(kLuminaireImageSize) + ", as bpm reads the file itself)")
      ->check(CLI::Range(16, 8192));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bpm: physically based rendering with backward photon maps; reads pbrt-v4 scenes"};
  app.require_subcommand(1);
  RenderRequest ra;
  CLI::App* render = add_render_command(app, ra);

  std::string cmp_a, cmp_b;
  CLI::App* compare =
      app.add_subcommand("compare", "Compare two EXR images (channel means, relative MSE)");
  compare->add_option("a", cmp_a, "Image to test")->required()->check(CLI::ExistingFile);
  compare->add_option("b", cmp_b, "Reference image")->required()->check(CLI::ExistingFile);

  LuminaireArgs la;
  add_luminaire_command(app, la);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
#ifdef BPM_HAVE_MPI
  MpiSession mpi(&argc, &argv);
  Team* team = mpi.team();
#else
  Team* team = nullptr;
#endif
  // With other processes, an error in one ends them all (they would wait for it forever). Most
  // errors before the render meet every process alike (the same files and flags): the others
  // give process 0 half a second to say it and end the job, and say it themselves, naming their
  // process, when the error is theirs alone (a file missing on one machine).
  bool rendering = false;
  auto fail = [&](const char* what) {
    if (!team) {
      std::fprintf(stderr, "bpm: error: %s\n", what);
      return 1;
    }
#ifdef BPM_HAVE_MPI
    if (team->rank() == 0) {
      std::fprintf(stderr, "bpm: error: %s\n", what);
    } else {
      if (!rendering) std::this_thread::sleep_for(std::chrono::milliseconds(500));
      std::fprintf(stderr, "bpm: error (process %d): %s\n", team->rank(), what);
    }
    std::fflush(stderr);
    mpi.abort(1);
#endif
    return 1;
  };
  try {
    if (*render) return run_render(ra, team, &rendering);
    if (*compare) return run_compare(cmp_a, cmp_b);
    if (app.got_subcommand("luminaire")) return run_luminaire(la);
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  return 0;
}
