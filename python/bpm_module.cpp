// The Python module `bpm` (docs/PYTHON.md): render, measure and sweep from a script or a notebook,
// with numpy arrays. A thin layer over render/render_job.h: its keyword arguments become the
// flags of `bpm render` (apps/render_flags.h), so a render asked for here and the same one asked
// for on the command line go through the same code and give the same image, bit for bit.
//
// A render runs on a thread of its own with the GIL released; the calling (main) thread waits for
// it, calls the progress callback and looks for Ctrl-C, which stops the render as it stops the
// program: the result so far is returned.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "base/error.h"
#include "base/interrupt.h"
#include "film/image_io.h"
#include "integrator/control.h"
#include "render/render_job.h"
#include "render_flags.h"

namespace py = pybind11;

namespace bpm {
namespace {

// ---------------------------------------------------------------------------------------------
// Scenes and their overrides

// A str or os.PathLike as a path.
std::string fspath(const py::handle& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

// Python's bools and numpy's.
bool is_bool(const py::handle& v) {
  return py::isinstance<py::bool_>(v) ||
         py::type::of(v).attr("__name__").cast<std::string>() == "bool_";
}

// A number that must be finite; `where` names it in the error.
double finite(const py::handle& v, const std::string& where) {
  double x;
  try {
    x = v.cast<double>();
  } catch (const py::cast_error&) {
    throw py::type_error(where + ": " + py::repr(v).cast<std::string>() + " is not a number");
  }
  // Finite in single precision too, where the scene keeps most numbers.
  if (!std::isfinite(float(x)))
    throw Error(where + ": " + py::repr(v).cast<std::string>() + " is not a finite number");
  return x;
}

Vec3 finite3(const std::array<double, 3>& v, const std::string& where) {
  for (double x : v)
    if (!std::isfinite(float(x))) throw Error(where + ": every coordinate must be a finite number");
  return Vec3(float(v[0]), float(v[1]), float(v[2]));
}

// A parameter as pbrt-v4 declares it ("float scale", "rgb reflectance") with a Python value: a
// number, a bool, a string or a sequence of them. `where` names the call in error messages.
Param make_param(const std::string& declaration, const py::handle& value,
                 const std::string& where) {
  std::istringstream in(declaration);
  std::string type, name, extra;
  in >> type >> name;
  if (name.empty() || (in >> extra))
    throw Error(where + ": a parameter is declared as \"TYPE NAME\", e.g. \"float scale\"; got \"" +
                declaration + "\"");
  Param p;
  p.type = canonical_param_type(type);
  if (p.type.empty()) throw Error(where + ": unknown parameter type \"" + type + "\"");
  p.name = name;
  p.loc = FileLoc{where, 0, 0};
  auto add = [&](py::handle v) {
    if (is_bool(v))
      p.bools.push_back(PyObject_IsTrue(v.ptr()) == 1);
    else if (py::isinstance<py::str>(v))
      p.strings.push_back(v.cast<std::string>());
    else
      p.numbers.push_back(finite(v, where));
  };
  if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value))
    add(value);
  else
    for (py::handle v : value) add(v);
  const bool wants_bools = p.type == "bool",
             wants_strings = p.type == "string" || p.type == "texture";
  const bool ok = p.count() > 0 && (wants_bools            ? p.bools.size() == p.count()
                                    : wants_strings        ? p.strings.size() == p.count()
                                    : p.type == "spectrum" ? p.numbers.size() == p.count() ||
                                                                 p.strings.size() == p.count()
                                                           : p.numbers.size() == p.count());
  if (!ok)
    throw Error(where + ": \"" + declaration + "\" takes " +
                (wants_bools     ? "bools"
                 : wants_strings ? "strings"
                                 : "numbers") +
                ", one or a sequence");
  return p;
}

// A pbrt-v4 scene parsed once, rendered as often as asked, each time with its overrides.
struct Scene {
  SceneFile file;
  std::string name;                    // the file as given, or "<string>" for text
  int renders = 0;                     // so far: the first one's record counts the parse
  int busy = 0;                        // renders reading it now: it may not change meanwhile
  std::vector<std::string> overrides;  // as called, for the record

  std::string where(const std::string& call) const { return name + " (" + call + ")"; }
};

// "name(a, b)" with the arguments' repr: an override as the record lists it.
std::string call_text(const std::string& name, std::initializer_list<py::object> args) {
  std::string text = name + "(";
  for (const py::object& a : args)
    text += (text.back() == '(' ? "" : ", ") + py::repr(a).cast<std::string>();
  return text + ")";
}

// An override: the scene must not be in a render; `apply` changes it, and then the call is
// recorded.
template <class Apply>
void override_scene(Scene& s, const std::string& name, const std::string& call, Apply&& apply) {
  if (s.busy > 0)
    throw Error(s.where(name) + ": the scene is being rendered; change it when the render is done");
  apply();
  s.overrides.push_back(call);
}

// A path-like object or a string naming an existing file, or one line ending in .pbrt, is a file;
// any other string is the scene's text.
Scene load_scene(const py::object& source) {
  Scene s;
  const py::module_ os = py::module_::import("os");
  std::string path;
  if (py::isinstance(source, os.attr("PathLike"))) {
    path = fspath(source);
  } else if (py::isinstance<py::str>(source)) {
    const std::string text = source.cast<std::string>();
    std::error_code ec;
    const bool one_line = text.find('\n') == std::string::npos;
    if (one_line && (text.ends_with(".pbrt") || std::filesystem::is_regular_file(text, ec)))
      path = text;
    else {
      // Relative names resolve against the folder current now, whenever the scene is built.
      const std::string here = std::filesystem::current_path().string();
      py::gil_scoped_release release;
      s.file = read_scene_text(text, here);
      s.name = "<string>";
      return s;
    }
  } else {
    throw py::type_error("a scene is a file's path or pbrt-v4 text");
  }
  py::gil_scoped_release release;
  s.file = read_scene_file(path);
  s.name = path;
  return s;
}

// The scene's lights as Scene.lights lists them: its LightSource directives in the file's order,
// then its shapes with an AreaLightSource.
struct LightRef {
  SceneEntity* params;  // the LightSource, or the shape's AreaLightSource
  Transform* world;     // the light's placement (for an area light, its shape's)
  const SceneEntity* directive;
};

std::vector<LightRef> scene_lights(Scene& s) {
  std::vector<LightRef> out;
  for (LightEntity& l : s.file.parsed.lights) out.push_back({&l, &l.world_from_light, &l});
  for (ShapeEntity& sh : s.file.parsed.shapes)
    if (sh.area_light) out.push_back({&*sh.area_light, &sh.world_from_object, &sh});
  return out;
}

LightRef light_at(Scene& s, int index) {
  const std::vector<LightRef> lights = scene_lights(s);
  const int n = int(lights.size());
  if (index < 0 || index >= n)
    throw py::index_error("light " + std::to_string(index) + " of " + std::to_string(n) +
                          " (Scene.lights lists them)");
  return lights[size_t(index)];
}

SceneEntity& material_at(Scene& s, const py::object& which) {
  ParsedScene& p = s.file.parsed;
  if (py::isinstance<py::str>(which)) {
    const std::string name = which.cast<std::string>();
    auto it = p.named_materials.find(name);
    if (it != p.named_materials.end()) return it->second;
    std::string names;
    for (const auto& [n, m] : p.named_materials) names += (names.empty() ? "" : ", ") + n;
    throw py::key_error("no material named \"" + name +
                        "\" (named: " + (names.empty() ? "none" : names) + ")");
  }
  if (!py::isinstance<py::int_>(which))
    throw py::type_error("a material is its name or the index of its Material directive");
  const int index = which.cast<int>();
  if (index < 0 || index >= int(p.materials.size()))
    throw py::index_error("material " + std::to_string(index) + " of " +
                          std::to_string(p.materials.size()) + " (Material directives)");
  return p.materials[size_t(index)];
}

void look_at(Scene& s, std::array<double, 3> eye, std::array<double, 3> target,
             std::array<double, 3> up) {
  const std::string where = s.where("look_at");
  const auto t =
      Transform::look_at(finite3(eye, where), finite3(target, where), finite3(up, where));
  if (!t) throw Error(where + ": eye and target coincide, or up is along the view");
  override_scene(s, "look_at",
                 call_text("look_at", {py::cast(eye), py::cast(target), py::cast(up)}), [&] {
                   if (!s.file.parsed.camera)
                     s.file.parsed.camera = CameraEntity{{"perspective", {}, {}}, {}, {}};
                   s.file.parsed.camera->camera_from_world = *t;
                 });
}

// Scene.set_camera, set_film, set_integrator, set_light, set_material: a parameter of one
// directive.
void set_camera(Scene& s, const std::string& decl, const py::object& v) {
  override_scene(s, "set_camera", call_text("set_camera", {py::str(decl), v}), [&] {
    if (!s.file.parsed.camera) throw Error(s.where("set_camera") + ": no Camera directive");
    s.file.parsed.camera->params.set(make_param(decl, v, s.where("set_camera")));
  });
}

void set_film(Scene& s, const std::string& decl, const py::object& v) {
  override_scene(s, "set_film", call_text("set_film", {py::str(decl), v}),
                 [&] { s.file.parsed.film.params.set(make_param(decl, v, s.where("set_film"))); });
}

void set_integrator(Scene& s, const std::string& decl, const py::object& v) {
  override_scene(s, "set_integrator", call_text("set_integrator", {py::str(decl), v}), [&] {
    SceneFile f = s.file;
    f.parsed.integrator.params.set(make_param(decl, v, s.where("set_integrator")));
    f.settings = integrator_settings(f.parsed);
    s.file = std::move(f);
  });
}

void set_light(Scene& s, int i, const std::string& decl, const py::object& v) {
  override_scene(s, "set_light", call_text("set_light", {py::int_(i), py::str(decl), v}), [&] {
    light_at(s, i).params->params.set(make_param(decl, v, s.where("set_light")));
  });
}

void translate_light(Scene& s, int i, std::array<double, 3> d) {
  const Vec3 offset = finite3(d, s.where("translate_light"));
  override_scene(s, "translate_light", call_text("translate_light", {py::int_(i), py::cast(d)}),
                 [&] {
                   Transform* world = light_at(s, i).world;
                   *world = Transform::translate(offset) * *world;
                 });
}

void set_material(Scene& s, const py::object& which, const std::string& decl, const py::object& v) {
  override_scene(s, "set_material", call_text("set_material", {which, py::str(decl), v}), [&] {
    material_at(s, which).params.set(make_param(decl, v, s.where("set_material")));
  });
}

py::list light_list(Scene& s) {
  py::list out;
  int i = 0;
  for (const LightRef& l : scene_lights(s)) {
    py::dict d;
    d["index"] = i++;
    d["type"] = l.params->name;
    d["area"] = l.params != l.directive;
    d["shape"] = l.params != l.directive ? l.directive->name : "";
    d["where"] = l.params->loc.str();
    out.append(d);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Renders

// What a render leaves: its film, and what writing it and its record need.
struct Result {
  std::shared_ptr<const Film> film;
  RenderRequest request;
  RenderOptions options;  // without its callbacks
  FilmSettings film_settings;
  nlohmann::json record;  // the JSON record, less its outputs until saved
};

// The flags of `bpm render` that the keyword arguments make, and the progress callback.
struct RenderCall {
  RenderRequest request;
  py::object progress = py::none();
};

// Keyword arguments whose flags would write files.
const char* const kNotFlags[] = {"output", "write_every", "resume"};

// A keyword's value as its flag's: (w, h) as WxH, a float as Python writes it (the shortest text
// that reads back as the same number, what a user would type).
std::string flag_value(const std::string& key, const py::handle& v) {
  if (key == "resolution" && py::isinstance<py::sequence>(v) && !py::isinstance<py::str>(v)) {
    if (py::len(v) != 2 || !py::isinstance<py::int_>(v[py::int_(0)]) ||
        !py::isinstance<py::int_>(v[py::int_(1)]))
      throw py::type_error("resolution is (width, height), two ints, or \"WxH\"");
    return py::str(v[py::int_(0)]).cast<std::string>() + "x" +
           py::str(v[py::int_(1)]).cast<std::string>();
  }
  if (py::isinstance<py::float_>(v)) return py::repr(v).cast<std::string>();
  if (py::isinstance<py::str>(v) || py::isinstance<py::int_>(v) || py::hasattr(v, "__float__") ||
      py::hasattr(v, "__index__"))
    return py::str(v).cast<std::string>();
  throw py::type_error(key + " = " + py::repr(v).cast<std::string>() +
                       ": a number, a string or a bool");
}

// Sensors as a sequence of (x, y, z, nx, ny, nz): the lines a sensor file would hold.
std::string sensor_lines(const py::handle& v) {
  std::string text;
  for (py::handle row : v) {
    if (!py::isinstance<py::sequence>(row) || py::len(row) != 6)
      throw py::type_error("sensors: each sensor is (x, y, z, nx, ny, nz); got " +
                           py::repr(row).cast<std::string>());
    std::vector<double> s;
    for (py::handle x : row) s.push_back(finite(x, "sensors"));
    char line[256];
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g %.17g %.17g %.17g\n", s[0], s[1], s[2],
                  s[3], s[4], s[5]);
    text += line;
  }
  if (text.empty()) throw Error("sensors: the list is empty");
  return text;
}

RenderCall render_call(const Scene& scene, const py::kwargs& kwargs) {
  RenderCall call;
  std::vector<std::string> args = {scene.name};
  bool quiet = true;
  std::string lines;
  for (const auto& [k, v] : kwargs) {
    std::string key = k.cast<std::string>();
    std::replace(key.begin(), key.end(), '-', '_');
    for (const char* bad : kNotFlags)
      if (key == bad)
        throw py::type_error("render() takes no \"" + key +
                             "\": Result.save(path) writes the files");
    if (key == "scene") throw py::type_error("render(): the scene is the first argument");
    if (key == "progress") {
      if (!v.is_none() && !PyCallable_Check(v.ptr()))
        throw py::type_error("progress must be a function (or None)");
      call.progress = py::reinterpret_borrow<py::object>(v);
      continue;
    }
    if (key == "quiet") {
      quiet = PyObject_IsTrue(v.ptr()) == 1;
      continue;
    }
    if (v.is_none()) continue;
    if (key == "sensors" && !py::isinstance<py::str>(v) && py::isinstance<py::sequence>(v)) {
      lines = sensor_lines(v);
      continue;
    }
    std::string flag = "--" + key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    if (is_bool(v)) {
      if (PyObject_IsTrue(v.ptr()) == 1) args.push_back(flag);
      continue;
    }
    if (key == "sensors" && !py::isinstance<py::str>(v))
      args.insert(args.end(), {flag, fspath(v)});
    else
      args.insert(args.end(), {flag, flag_value(key, v)});
  }
  if (quiet) args.push_back("--quiet");
  call.request = parse_render_request(args);
  if (!lines.empty()) {
    call.request.sensor_lines = lines;
    call.request.sensors = "<sensors>";
  }
  return call;
}

// The render itself, on the render thread: what the program's `bpm render` does up to its outputs.
Result run(const Scene& scene, const RenderRequest& request, double parse_s,
           const std::function<void(const RenderProgress&)>& on_progress) {
  const int warnings_before = warning_count();
  const auto t = Clock::now();
  const LoadedScene ls = build_scene(scene.file, request);
  const double build_s = since(t);
  RenderOptions opt = render_options(request, ls, scene.file.settings);
  check_film_memory(request, ls, opt, false, false);
  auto film =
      std::make_shared<Film>(ls.film.width, ls.film.height, request.m_images, opt.sensors.size());
  film->set_spectral(ls.film.spectral);
  opt.on_progress = on_progress;
  const RenderStats st = render(ls, opt, film.get());
  opt.on_progress = nullptr;
  Result r{film, request, opt, ls.film, {}};
  r.record = run_record(request, ls, opt, st, *film, OutputPaths{}, {parse_s, build_s, 0});
  r.record.erase("outputs");
  r.record.erase("sensors");
  r.record["stages_s"].erase("write_images");
  // This render's warnings (the count is the process's); the scene's overrides.
  r.record["scene_stats"]["warnings"] = warning_count() - warnings_before;
  if (!scene.overrides.empty()) r.record["overrides"] = scene.overrides;
  return r;
}

// What the render thread shares with the calling one.
struct Exchange {
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::optional<RenderProgress> latest;
  std::exception_ptr error;
};

py::dict progress_dict(const RenderProgress& p) {
  py::dict d;
  d["passes"] = p.passes;
  d["seconds"] = p.seconds;
  d["delta"] = p.delta;
  d["bias"] = p.bias;
  return d;
}

// Waits for the render thread: calls the progress callback, and stops the render on Ctrl-C (the
// result so far is returned), on a callback that returns False, or on one that raises (raised
// again once the render has stopped).
void wait_for(Exchange& x, const py::object& progress,
              std::optional<py::error_already_set>* raised) {
  for (;;) {
    bool done;
    std::optional<RenderProgress> p;
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(x.m);
      x.cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return x.done; });
      done = x.done;
      p.swap(x.latest);
    }
    if (PyErr_CheckSignals() != 0) {
      if (PyErr_ExceptionMatches(PyExc_KeyboardInterrupt))
        PyErr_Clear();
      else if (!*raised)
        raised->emplace();  // fetches the error
      interrupt_flag() = true;
    }
    if (p && !progress.is_none() && !*raised && !interrupted()) {
      try {
        const py::object answer = progress(progress_dict(*p));
        // False (or anything false but None) stops the render.
        if (!answer.is_none() && PyObject_Not(answer.ptr()) != 0) interrupt_flag() = true;
      } catch (py::error_already_set& e) {
        // Ctrl-C while the callback ran is Ctrl-C; anything else is the callback's error.
        if (!e.matches(PyExc_KeyboardInterrupt)) raised->emplace(std::move(e));
        interrupt_flag() = true;
      }
    }
    if (done) return;
  }
}

// Renders run one at a time in a process (they share the interrupt flag, the thread limit and the
// image writer's threads): a render waits for the one before, with the GIL released. A render
// started from a progress callback (the thread whose render is running) is an error.
class RenderTurn {
 public:
  RenderTurn() {
    if (owner_.load() == std::this_thread::get_id())
      throw Error("a render is running on this thread: a progress callback cannot start another");
    py::gil_scoped_release release;
    lock_ = std::unique_lock<std::mutex>(mutex_);
    owner_ = std::this_thread::get_id();
  }
  ~RenderTurn() { owner_ = std::thread::id(); }

 private:
  static inline std::mutex mutex_;
  static inline std::atomic<std::thread::id> owner_;
  std::unique_lock<std::mutex> lock_;
};

// The scene may not change while a render reads it.
struct Busy {
  Scene& scene;
  explicit Busy(Scene& s) : scene(s) { ++scene.busy; }
  ~Busy() { --scene.busy; }
};

Result render_scene(Scene& scene, const py::kwargs& kwargs) {
  const RenderCall call = render_call(scene, kwargs);
  RenderTurn turn;
  Busy busy(scene);
  const double parse_s = scene.renders++ == 0 ? scene.file.parse_s : 0;
  Exchange x;
  Result result;
  interrupt_flag() = false;
  auto on_progress = [&x](const RenderProgress& p) {
    std::lock_guard<std::mutex> lock(x.m);
    x.latest = p;
  };
  std::thread worker([&] {
    try {
      result = run(scene, call.request, parse_s, on_progress);
    } catch (...) {
      x.error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(x.m);
    x.done = true;
    x.cv.notify_all();
  });
  std::optional<py::error_already_set> raised;
  try {
    wait_for(x, call.progress, &raised);
  } catch (...) {
    interrupt_flag() = true;  // the render stops before its stack goes
    py::gil_scoped_release release;
    worker.join();
    throw;
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  interrupt_flag() = false;
  if (raised) throw std::move(*raised);
  if (x.error) std::rethrow_exception(x.error);
  return result;
}

// ---------------------------------------------------------------------------------------------
// Results as numpy arrays

py::array_t<float> array(const std::vector<float>& v, std::vector<py::ssize_t> shape,
                         float scale = 1) {
  py::array_t<float> a(shape);
  float* out = a.mutable_data();
  for (size_t i = 0; i < v.size(); ++i) out[i] = v[i] * scale;
  return a;
}

py::array_t<float> rgb(const Result& r, const std::vector<float>& v, bool scaled = true) {
  return array(v, {r.film->height(), r.film->width(), 3},
               scaled ? r.film_settings.imaging_ratio : 1.0f);
}

py::array_t<float> plane(const Result& r, const std::vector<float>& v) {
  return array(v, {r.film->height(), r.film->width()});
}

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

py::array_t<double> sensor_values(const Result& r, double (Film::*get)(size_t) const) {
  py::array_t<double> a(py::ssize_t(r.film->sensor_count()));
  for (size_t i = 0; i < r.film->sensor_count(); ++i) a.mutable_data()[i] = ((*r.film).*get)(i);
  return a;
}

void save(const Result& r, const py::object& path) {
  RenderRequest request = r.request;
  request.output = fspath(path);
  py::gil_scoped_release release;
  const OutputPaths paths = checked_output_paths(request, r.film_settings);
  const auto t = Clock::now();
  write_outputs(r.film_settings, r.options, *r.film, paths);
  nlohmann::json rec = r.record;
  rec["stages_s"]["write_images"] = since(t);
  record_outputs(request, r.options, *r.film, paths, &rec);
  write_text_atomic(paths.json, rec.dump(2) + "\n");
}

py::array_t<float> read_exr_rgb(const py::object& path) {
  const Image img = read_exr(fspath(path));
  return array(img.rgb, {img.height, img.width, 3});
}

// ---------------------------------------------------------------------------------------------
// The module

const char* const kRenderDoc = R"(Renders a scene and returns a Result.

Keyword arguments are the flags of `bpm render` with their dashes as underscores (docs/USAGE.md):
integrator ("path", "bpm" or "fpm"), time (seconds), spp, iterations, accuracy, resolution
("WxH" or (w, h)), seed, threads, maxdepth, memory, sensors (a file, or a sequence of
(x, y, z, nx, ny, nz)), no_image, m_images, and each integrator's settings (k0, k1, photons,
diffuse_depth, radius_policy, no_guide=True, ...). A flag without a value is a bool; None leaves a
setting to the scene file. quiet=False prints the progress line on stderr; progress=f calls f with
a dict (passes, seconds, delta, bias) from the calling thread twice a second, and a return of False
stops the render. Ctrl-C stops the render and returns the result so far (stop_reason "interrupted").
Raises bpm.Error with the program's message (FILE:LINE:COLUMN: ...) on a bad scene or setting.)";

void bind_scene(py::module_& m) {
  py::class_<Scene>(m, "Scene",
                    "A pbrt-v4 scene, parsed once and rendered as often as asked, each time with "
                    "the overrides set so far.")
      .def(py::init(&load_scene), py::arg("source"),
           "A file's path, or pbrt-v4 text (relative names resolve against the current folder).")
      .def_readonly("name", &Scene::name)
      .def_property_readonly(
          "lights", &light_list,
          "The lights: the LightSource directives in the file's order, then the shapes with an "
          "AreaLightSource (area True, shape its type): index, type, where.")
      .def_property_readonly(
          "materials",
          [](const Scene& s) {
            std::vector<std::string> names;
            for (const auto& [n, e] : s.file.parsed.named_materials) names.push_back(n);
            return names;
          },
          "The names of the named materials (MakeNamedMaterial).")
      .def("look_at", &look_at, py::arg("eye"), py::arg("target"), py::arg("up"),
           "Replaces the camera's whole transform with that of a LookAt directive (a transform the "
           "file gives before its LookAt, such as a Scale -1 1 1, is dropped).")
      .def("set_camera", &set_camera, py::arg("parameter"), py::arg("value"),
           "Sets a Camera parameter, e.g. set_camera(\"float fov\", 40).")
      .def("set_film", &set_film, py::arg("parameter"), py::arg("value"),
           "Sets a Film parameter, e.g. set_film(\"float iso\", 200).")
      .def("set_integrator", &set_integrator, py::arg("parameter"), py::arg("value"),
           "Sets a parameter of the Integrator line.")
      .def("set_light", &set_light, py::arg("index"), py::arg("parameter"), py::arg("value"),
           "Sets a parameter of light `index` (Scene.lights), e.g. set_light(0, \"float scale\", "
           "2).")
      .def("translate_light", &translate_light, py::arg("index"), py::arg("offset"),
           "Moves light `index` by offset (world units), after any move before; an area light "
           "moves with its shape.")
      .def("set_material", &set_material, py::arg("material"), py::arg("parameter"),
           py::arg("value"),
           "Sets a parameter of a named material (by name) or of the file's n-th Material "
           "directive (by index), e.g. set_material(\"glass\", \"float eta\", 1.6).")
      .def_readonly("overrides", &Scene::overrides, "The overrides set so far, as called.")
      .def("render", &render_scene, kRenderDoc);
}

void bind_result(py::module_& m) {
  using R = Result;
  py::class_<R>(m, "Result", "A finished render: its image, errors, sensors and statistics.")
      .def_property_readonly(
          "image",
          [](const R& r) {
            return array(r.film->image(r.film_settings.imaging_ratio).rgb,
                         {r.film->height(), r.film->width(), 3});
          },
          "H x W x 3 linear sRGB, as OUT.exr's R, G, B (times the film's imaging ratio).")
      .def_property_readonly(
          "rms", [](const R& r) { return rgb(r, r.film->rms_rgb()); },
          "H x W x 3 standard error of each pixel (eq. 5), in the image's units.")
      .def_property_readonly(
          "bias",
          [](const R& r) -> py::object {
            if (!r.film->has_bias()) return py::none();
            return rgb(r, r.film->bias_rgb());
          },
          "H x W x 3 signed bias estimate (the photon methods), or None (path).")
      .def_property_readonly(
          "total_error",
          [](const R& r) {
            return rgb(r, r.film->has_bias() ? r.film->total_rms_rgb() : r.film->rms_rgb());
          },
          "H x W x 3 noise and bias together.")
      .def_property_readonly(
          "luminance", [](const R& r) { return plane(r, r.film->luminance_image()); },
          "H x W luminance in cd/m^2 (without the imaging ratio).")
      .def_property_readonly(
          "luminance_error",
          [](const R& r) {
            return plane(r, r.film->has_bias() ? r.film->total_rms_luminance() : r.film->rms());
          },
          "H x W total error of the luminance in cd/m^2.")
      .def_property_readonly(
          "passes", [](const R& r) { return plane(r, r.film->pass_counts()); },
          "H x W passes (samples) per pixel.")
      .def_property_readonly(
          "sensors", [](const R& r) { return sensor_values(r, &Film::sensor_mean); },
          "Illuminance of each sensor in lux.")
      .def_property_readonly(
          "sensor_errors", [](const R& r) { return sensor_values(r, &Film::sensor_total_error); },
          "Total error (noise and bias) of each sensor in lux.")
      .def_property_readonly(
          "stats", [](const R& r) { return json_to_python(r.record); },
          "The JSON record's contents (settings, result, the integrator's statistics).")
      .def_property_readonly(
          "stop_reason",
          [](const R& r) { return r.record["result"]["stop_reason"].get<std::string>(); },
          "samples, time, accuracy or interrupted.")
      .def("save", &save, py::arg("path"),
           "Writes PATH.exr and the files the program writes beside it (.png, .luminance.png, "
           ".error.png, .bias.png, .json; .sensors.csv with sensors), each atomically.");
}

}  // namespace
}  // namespace bpm

PYBIND11_MODULE(bpm, m) {
  m.doc() = "bpm: physically based rendering with backward photon maps, from Python";
  py::register_exception<bpm::Error>(m, "Error", PyExc_RuntimeError);
  bpm::bind_scene(m);
  bpm::bind_result(m);
  m.def(
      "render",
      [](const py::object& scene, const py::kwargs& kwargs) {
        if (py::isinstance<bpm::Scene>(scene))
          return bpm::render_scene(scene.cast<bpm::Scene&>(), kwargs);
        bpm::Scene loaded = bpm::load_scene(scene);
        return bpm::render_scene(loaded, kwargs);
      },
      py::arg("scene"), bpm::kRenderDoc);
  m.def("read_exr", &bpm::read_exr_rgb, py::arg("path"),
        "The R, G, B channels of an EXR file as an H x W x 3 array.");
}
