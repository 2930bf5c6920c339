// abcube.Renderer and abcube.RenderResult: one render call with keyword overrides, the GIL
// released while the library renders (include/abcube/renderer.hpp).
#include <algorithm>
#include <cmath>
#include <csignal>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <abcube/options.hpp>
#include <abcube/report.hpp>
#include <nlohmann/json.hpp>

#include <pybind11/stl.h>

#include "py_convert.hpp"

namespace abcube {

namespace {

// What render() returns when AOVs or stats are asked for.
struct PyRenderResult {
  py::object image;  // float32 H x W x 3
  py::dict aovs;     // name -> float32 H x W (H x W x 3 for "normal")
  py::object stats;  // dict (json.loads of RenderStats::json) or None
};

std::string join(const std::vector<std::string>& names, const char* separator) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : separator) + n;
  return out;
}

// Sets one option of the table; a bad value is named as the keyword was (`shown`).
void set_option(RenderSetup& setup, const std::string& key, const std::string& shown, const py::handle& value) {
  try {
    set_render_option(setup, key, json_text(value, shown));
  } catch (const OptionError& e) {
    throw InputError(shown + ": " + e.reason);
  }
}

// The keywords of Renderer.render applied to a setup: every job option of the table by its
// key, "camera" as a dict of position, look_at, up, fov_y, width, height, and the older
// keywords plan_everything (plan="everything") and side_structure (not map_only).
RenderSetup setup_from_kwargs(const py::kwargs& kwargs, bool* want_stats, py::object* progress) {
  RenderSetup setup;
  for (const auto& item : kwargs) {
    const std::string key = py::str(item.first);
    const py::handle value = item.second;
    if (key == "stats") {
      *want_stats = bool_arg(value, "stats");
      continue;
    }
    if (value.is_none()) continue;  // the default
    if (key == "progress") {
      if (!PyCallable_Check(value.ptr()))
        throw InputError("progress: must be callable (stage, done), got " + type_name(value));
      *progress = py::reinterpret_borrow<py::object>(value);
      continue;
    }
    if (key == "camera") {
      if (!py::isinstance<py::dict>(value)) {
        throw InputError("camera: must be a dict with any of position, look_at, up, fov_y, width, height, got " +
                         type_name(value));
      }
      static const std::vector<std::string> known = {"position", "look_at", "up", "fov_y", "width", "height"};
      for (const auto& c : py::reinterpret_borrow<py::dict>(value)) {
        const std::string name = string_arg(c.first, "camera key");
        if (std::find(known.begin(), known.end(), name) == known.end()) {
          throw InputError("camera." + name + ": unknown key (" + join(known, ", ") + ")" + did_you_mean(name, known));
        }
        set_option(setup, name == "position" ? "camera_position" : name, "camera." + name, c.second);
      }
    } else if (key == "plan_everything") {
      if (bool_arg(value, key)) set_render_option(setup, "plan", "\"everything\"");
    } else if (key == "side_structure") {
      set_render_option(setup, "map_only", bool_arg(value, key) ? "false" : "true");
    } else {
      const OptionSpec* spec = find_render_option(key);
      if (!spec || spec->flag == key) {
        std::vector<std::string> known = {"camera", "stats", "progress", "plan_everything", "side_structure"};
        for (const OptionSpec& o : render_option_table()) {
          if (o.scope == OptionScope::job) known.push_back(o.key);
        }
        throw InputError("render: unknown keyword '" + key + "'" + did_you_mean(key, known) +
                         " (help(abcube.Renderer.render) lists them)");
      }
      if (spec->scope == OptionScope::process) {
        throw InputError(key + ": a setting of the Renderer: abcube.Renderer(" + key + "=...)");
      }
      if (spec->scope == OptionScope::scene) {
        throw InputError(key + ": a setting of loading: abcube.load_scene(path, " + key + "=...)");
      }
      set_option(setup, spec->key, key, value);
    }
  }
  return setup;
}

// Ctrl-C during a render gives KeyboardInterrupt, as everywhere else in Python. While the
// GIL is released, Python's own SIGINT handler only marks the signal for the main thread's
// next bytecode, which would come after the render. So a render called from the main
// thread, while SIGINT has Python's default handler, puts a C handler in its place for its
// duration: it asks the render to stop at its next check (request_stop: async-signal-safe,
// process-wide until this render returns: a render of another thread that checks meanwhile
// stops with RuntimeError "interrupted (SIGINT)"), and KeyboardInterrupt is raised once the
// render has returned. Constructed and destroyed with the GIL held.
class SigintStopsRender {
 public:
  SigintStopsRender() {
    const py::module_ threading = py::module_::import("threading"), signal = py::module_::import("signal");
    active_ = threading.attr("current_thread")().is(threading.attr("main_thread")()) &&
              signal.attr("getsignal")(signal.attr("SIGINT")).is(signal.attr("default_int_handler"));
    if (!active_) return;
    seen_ = 0;
    struct sigaction action {};
    action.sa_handler = on_sigint;
    sigemptyset(&action.sa_mask);
    active_ = sigaction(SIGINT, &action, &previous_) == 0;
  }
  SigintStopsRender(const SigintStopsRender&) = delete;
  SigintStopsRender& operator=(const SigintStopsRender&) = delete;
  // Python's handler back; true when a SIGINT came while ours was in place (the stop it
  // asked for is then withdrawn, so that the next render runs).
  bool restore() {
    if (!active_) return false;
    sigaction(SIGINT, &previous_, nullptr);
    active_ = false;
    if (seen_ == 0) return false;
    clear_stop_request();
    return true;
  }
  ~SigintStopsRender() { restore(); }

 private:
  static void on_sigint(int signal_number) {
    seen_ = 1;
    request_stop(signal_number);
  }
  static volatile std::sig_atomic_t seen_;
  bool active_ = false;
  struct sigaction previous_ {};
};
volatile std::sig_atomic_t SigintStopsRender::seen_ = 0;

// Renders with the GIL released: arguments converted before, results after.
py::object render(Renderer& renderer, const py::handle& scene_object, const py::kwargs& kwargs) {
  if (!py::isinstance<Scene>(scene_object)) {
    throw InputError("scene: must be an abcube.Scene (load_scene, scene_from_dict), got " + type_name(scene_object));
  }
  bool want_stats = false;
  py::object progress;  // a callable (stage, done), or None
  const RenderSetup setup = setup_from_kwargs(kwargs, &want_stats, &progress);
  RenderOptions options = setup.render;
  options.stats = want_stats;
  // The callback runs on the rendering thread with the GIL taken for it; one that raises is
  // called no more, and its exception is raised when the render returns.
  std::optional<py::error_already_set> raised;
  if (progress) {
    const py::object* call = &progress;  // outlives the render; copied as a pointer, no reference count touched
    options.progress = [call, &raised](const std::string& stage, double done) {
      if (raised) return;
      py::gil_scoped_acquire gil;
      try {
        (*call)(stage, done);
      } catch (py::error_already_set& e) {
        raised.emplace(std::move(e));
      }
    };
  }
  const bool want_result = !options.aovs.empty() || options.stats;
  // A cheap copy sharing the loaded data; loaded again only when set= replaces values.
  const Scene scene = scene_object.cast<Scene>().with_overrides(setup.set);
  try {
    refuse_unused_options(scene, options);
  } catch (const OptionError& e) {  // named as the keyword
    throw InputError(e.key + ": " + e.reason);
  }
  RenderResult result;
  SigintStopsRender sigint;
  try {
    py::gil_scoped_release release;
    result = renderer.render(scene, options);
  } catch (const Interrupted&) {
    if (!sigint.restore()) throw;
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  if (sigint.restore()) {  // Ctrl-C after the render's last check: the result is dropped, as Python would
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  if (raised) throw std::move(*raised);
  if (!want_result) return image_to_array(std::move(result.image));

  // The image, the AOVs and the stats as Python objects.
  PyRenderResult out;
  out.image = image_to_array(std::move(result.image));
  for (auto& [name, image] : result.aovs) out.aovs[py::str(name)] = image_to_array(std::move(image));
  out.stats =
      result.stats.json.empty() ? py::object(py::none()) : py::module_::import("json").attr("loads")(result.stats.json);
  return py::cast(std::move(out));
}

Renderer* make_renderer(const py::handle& gl, const py::handle& threads, const py::handle& gl_device) {
  RendererOptions options;
  options.gl = string_arg(gl, "gl");
  options.threads = int_arg(threads, "threads");
  options.gl_device = int_arg(gl_device, "gl_device");
  return new Renderer(options);
}

constexpr const char* RENDERER_DOC = R"doc(Renders Scenes into float32 numpy arrays.

Renderer(gl="auto", threads=0, gl_device=-1)
  gl: auto | egl | egl-device | egl-surfaceless | osmesa | none. GL is opened on the first
      render that needs it (method "gpu", and the cube-map passes that use it); a forced
      path that fails raises RuntimeError naming the reason.
  threads: worker threads per render (0: every core).
  gl_device: EGL device index (-1: ABCUBE_EGL_DEVICE, else the first hardware one).

Threads: the GIL is released while a render runs. Several Python threads may call
render() on DIFFERENT Renderer objects at once (each its own Renderer; the same Scene is
fine). Calls on ONE Renderer are serialized: a second caller waits for the first. A
Renderer that opened GL must be used from the thread that opened it (GL contexts are
current per thread); from another thread render() raises RuntimeError. Give each thread
(or each worker process) its own Renderer.)doc";

constexpr const char* RENDER_DOC_HEAD = R"doc(render(scene, **options)

Renders `scene` and returns its image: a float32 array H x W x 3 (linear RGB, row 0 at the
top), identical to the float EXR `abcube render` writes for the same inputs. With `aovs`
or stats=True it returns a RenderResult instead: .image, .aovs (name -> float32 H x W,
H x W x 3 for "normal"), .stats (the CLI's --stats JSON as a dict, or None).

Every option of `abcube render` is a keyword, by its snake_case name; None or absent means
the default (mostly: the scene's own value). Values are checked as the command line and
`abcube batch` check them, with the same messages; an option the render's method does not
use is refused (SceneError), as it is there.
  camera: a dict with any of position, look_at, up, fov_y, width, height (only the keys
          given change).
  set: a dict {"camera.fov_y": 30, "lights[0].position": [1, 4, 2], ...} of scene values
       replaced before the scene is read (the scene is loaded again from its source).
  stats: True for the stats dict.
  progress: a callable (stage, done) called now and then on the rendering thread (the GIL
            taken for it) with a pass's name ("shading", "cube A-buffer", "raytrace",
            "gpu passes", ...) and its share done in [0, 1]; an exception it raises ends
            its calls and is raised when the render returns.
  plan_everything (True: plan="everything") and side_structure (False: map_only=True) are
  taken too.

The options:
)doc";

constexpr const char* RENDER_DOC_TAIL = R"doc(
A bad argument or scene raises SceneError (a ValueError) naming it; other failures
RuntimeError. The GIL is released while the render runs (see Renderer). Ctrl-C (SIGINT,
with Python's default handler) stops a render called from the main thread at its next
check and raises KeyboardInterrupt.)doc";

// The render docstring: its head, one line per job option of the table, its tail.
const std::string& render_doc() {
  static const std::string doc = [] {
    std::string d = RENDER_DOC_HEAD;
    for (const OptionSpec& s : render_option_table()) {
      if (s.scope != OptionScope::job) continue;
      std::string line = "  " + s.key + ": " + s.help;
      if (!s.choices.empty()) line += " (" + join(s.choices, " | ") + ")";
      if (s.kind == OptionKind::method) line += " (" + join(method_names(), " | ") + ")";
      if (!s.unit.empty()) line += "; " + s.unit;
      line += "; default: " + s.default_text;
      const std::vector<std::string> readers = methods_reading(s.key);
      if (!readers.empty()) line += "; methods: " + join(readers, ", ");
      d += line + "\n";
    }
    return d + RENDER_DOC_TAIL;
  }();
  return doc;
}

}  // namespace

// abcube.report: the comparison page, as `abcube report`.
py::dict report(const py::handle& scene_object, const py::handle& dir, const py::handle& methods,
                const py::handle& sweep, const py::handle& crosscheck, const py::handle& gl,
                const py::handle& gl_device, const py::kwargs& kwargs) {
  if (!py::isinstance<Scene>(scene_object)) {
    throw InputError("scene: must be an abcube.Scene (load_scene, scene_from_dict), got " + type_name(scene_object));
  }
  ReportOptions o;
  const std::string folder = path_arg(dir, "dir");
  if (!methods.is_none()) {
    if (py::isinstance<py::str>(methods) || !py::isinstance<py::sequence>(methods)) {
      throw InputError("methods: must be a list of method names, got " + type_name(methods));
    }
    o.methods.clear();
    for (const py::handle m : methods) o.methods.push_back(string_arg(m, "methods[]"));
  }
  if (!sweep.is_none()) {
    if (!py::isinstance<py::sequence>(sweep)) throw InputError("sweep: must be a list of cube resolutions N");
    for (const py::handle n : sweep) o.sweep.push_back(int_arg(n, "sweep[]"));
  }
  o.crosscheck = bool_arg(crosscheck, "crosscheck");
  o.renderer.gl = string_arg(gl, "gl");
  o.renderer.gl_device = int_arg(gl_device, "gl_device");
  bool want_stats = false;
  py::object progress;
  const RenderSetup setup = setup_from_kwargs(kwargs, &want_stats, &progress);
  if (progress) throw InputError("progress: report() reports its renders itself; give it to Renderer.render");
  o.render = setup.render;
  const Scene scene = scene_object.cast<Scene>().with_overrides(setup.set);
  ReportResult r;
  {
    py::gil_scoped_release release;
    r = write_report(scene, folder, o);
  }
  py::dict out = py::module_::import("json").attr("loads")(r.json);
  out["index_html"] = r.index_html;
  return out;
}

// The option table as Python data: a list of dicts, one an option.
py::list option_table() {
  static const char* const KINDS[] = {"choice", "integer", "number", "flag",    "path",
                                      "text",   "vec3",    "names",  "setting", "choice"};
  static const char* const SCOPES[] = {"job", "process", "scene"};
  py::list out;
  for (const OptionSpec& s : render_option_table()) {
    py::dict d;
    d["key"] = s.key;
    d["flag"] = s.flag;
    d["kind"] = KINDS[static_cast<int>(s.kind)];
    d["scope"] = SCOPES[static_cast<int>(s.scope)];
    d["choices"] = s.kind == OptionKind::method ? method_names() : s.choices;  // a method: the registered ones
    if (s.kind == OptionKind::integer || s.kind == OptionKind::number) d["range"] = py::make_tuple(s.min, s.max);
    d["default"] = s.default_text;
    d["unit"] = s.unit;
    d["methods"] = methods_reading(s.key);
    d["help"] = s.help;
    d["aliases"] = s.aliases;
    out.append(d);
  }
  return out;
}

void bind_renderer(py::module_& m) {
  m.def("report", &report, py::arg("scene"), py::arg("dir"), py::kw_only(), py::arg("methods") = py::none(),
        py::arg("sweep") = py::none(), py::arg("crosscheck") = true, py::arg("gl") = "auto", py::arg("gl_device") = -1,
        R"doc(report(scene, dir, *, methods=None, sweep=None, crosscheck=True, gl="auto", gl_device=-1, **options)

Writes the comparison page of `abcube report` into the folder `dir`: the scene rendered by
each method (default: abuffer, gpu, hybrid, zbuffer, envmap) and by the exact tracer,
their errors (per method, per kind of surface and per object), heat maps, time per pass,
abuffer again at each cube resolution N of `sweep` (speed against error), and the GPU
against the CPU (crosscheck=True, where GL works). The other keywords are render options,
as Renderer.render takes them (width=, height=, camera=, set=, max_depth=, ...). Returns
report.json's content as a dict, with "index_html" the page's path. SceneError for a bad
argument; a method that cannot render here is on the page with its reason.)doc");
  m.def("render_options", &option_table,
        R"doc(The render options, one dict each: key (the keyword of Renderer.render and the batch
job key), flag (the command line's), kind, scope ("job": any render; "process": the
Renderer's; "scene": load_scene's), choices, range, default, unit, methods (those that use
it; empty: every method), help, aliases. The command line, abcube batch and this module
all read their options, checks and help from this one table.)doc");
  py::class_<PyRenderResult>(m, "RenderResult", "What Renderer.render returns when aovs or stats are asked for.")
      .def_readonly("image", &PyRenderResult::image, "float32 H x W x 3, linear RGB.")
      .def_readonly("aovs", &PyRenderResult::aovs, "dict name -> float32 H x W (H x W x 3 for \"normal\").")
      .def_readonly("stats", &PyRenderResult::stats,
                    "dict: the CLI's --stats JSON (plan, timings_ms, counts, memory, GL path), "
                    "or None without stats=True.")
      .def("__repr__", [](const PyRenderResult& r) {
        return "<abcube.RenderResult image " + std::string(py::str(r.image.attr("shape"))) + ", aovs " +
               std::string(py::str(py::list(r.aovs))) + ", stats " + (r.stats.is_none() ? "None" : "{...}") + ">";
      });

  py::class_<Renderer>(m, "Renderer", RENDERER_DOC)
      .def(py::init(&make_renderer), py::arg("gl") = "auto", py::arg("threads") = 0, py::arg("gl_device") = -1)
      .def(
          "render",
          [](Renderer& self, const py::object& scene, const py::kwargs& kwargs) { return render(self, scene, kwargs); },
          py::arg("scene"), render_doc().c_str())
      .def_property_readonly("gl_path", &Renderer::gl_path,
                             "The GL path opened (\"\" before the first GL render; \"none\" "
                             "when GL was not wanted or not found under auto).")
      .def_property_readonly("gl_renderer", &Renderer::gl_renderer, "GL_RENDERER of that path.")
      .def_property_readonly("renders", &Renderer::renders, "Renders done so far.");
}

}  // namespace abcube
