// abcube.Renderer and abcube.RenderResult: one render call with keyword overrides, the GIL
// released while the library renders (include/abcube/renderer.hpp).
#include <csignal>
#include <string>
#include <utility>
#include <vector>

#include "py_convert.hpp"

namespace abcube {

namespace {

// What render() returns when AOVs or stats are asked for.
struct PyRenderResult {
  py::object image;  // float32 H x W x 3
  py::dict aovs;     // name -> float32 H x W (H x W x 3 for "normal")
  py::object stats;  // dict (json.loads of RenderStats::json) or None
};

// The keyword arguments of Renderer.render, in signature order (None: the default).
struct RenderArgs {
  py::object method, cube_res, max_depth, camera, aovs, stats, timeout, reference, threads,
      search, refine, theta_max_deg, refraction, envmap_lookup, error_target, fresnel,
      max_layers, max_memory_mib, max_pixels, plan_everything, reference_image, resolve, side_structure,
      gpu_mirrors, gpu_shadows, gpu_max_views, gpu_shading;
};

// Copies the keyword arguments given into RenderOptions; the others keep the struct's
// defaults, which mean "the scene's own value".
RenderOptions options_from_args(const RenderArgs& a) {
  RenderOptions o;
  if (!a.method.is_none()) o.method = string_arg(a.method, "method");
  if (!a.cube_res.is_none()) o.cube_resolution = int_arg(a.cube_res, "cube_res");
  if (!a.max_depth.is_none()) o.max_depth = int_arg(a.max_depth, "max_depth");
  if (!a.camera.is_none()) o.camera = camera_arg(a.camera);
  if (!a.aovs.is_none()) {
    if (py::isinstance<py::str>(a.aovs) || !py::isinstance<py::sequence>(a.aovs)) {
      throw InputError("aovs: must be a list of names (distance, normal, object_id, fallback), got " +
                       type_name(a.aovs));
    }
    for (const py::handle name : a.aovs) o.aovs.push_back(string_arg(name, "aovs[]"));
  }
  o.stats = bool_arg(a.stats, "stats");
  if (!a.timeout.is_none()) {
    o.timeout_s = float_arg(a.timeout, "timeout");
    if (!(o.timeout_s > 0) || o.timeout_s > 1e9) {
      throw InputError("timeout: must be a number of seconds > 0 (None: no limit), got " +
                       std::string(py::str(a.timeout)));
    }
  }
  o.reference = bool_arg(a.reference, "reference");
  if (!a.threads.is_none()) o.threads = int_arg(a.threads, "threads");
  if (!a.search.is_none()) o.search = string_arg(a.search, "search");
  if (!a.refine.is_none()) o.refine = string_arg(a.refine, "refine");
  if (!a.theta_max_deg.is_none()) o.theta_max_deg = float_arg(a.theta_max_deg, "theta_max_deg");
  if (!a.refraction.is_none()) o.refraction = string_arg(a.refraction, "refraction");
  if (!a.envmap_lookup.is_none()) o.envmap_lookup = string_arg(a.envmap_lookup, "envmap_lookup");
  if (!a.resolve.is_none()) o.resolve = string_arg(a.resolve, "resolve");
  if (!a.side_structure.is_none()) o.side_structure = bool_arg(a.side_structure, "side_structure");
  if (!a.error_target.is_none()) o.error_target = float_arg(a.error_target, "error_target");
  if (!a.fresnel.is_none()) o.fresnel = bool_arg(a.fresnel, "fresnel");
  if (!a.max_layers.is_none()) {
    const uint64_t layers = unsigned_arg(a.max_layers, "max_layers");
    if (layers > UINT32_MAX) throw InputError("max_layers: must be < 2^32");
    o.max_layers = static_cast<uint32_t>(layers);
  }
  if (!a.max_memory_mib.is_none()) o.max_memory_mib = unsigned_arg(a.max_memory_mib, "max_memory_mib");
  if (!a.max_pixels.is_none()) o.max_pixels = unsigned_arg(a.max_pixels, "max_pixels");
  o.plan_everything = bool_arg(a.plan_everything, "plan_everything");
  if (!a.reference_image.is_none()) o.reference_image = path_arg(a.reference_image, "reference_image");
  if (!a.gpu_mirrors.is_none()) o.gpu_mirrors = string_arg(a.gpu_mirrors, "gpu_mirrors");
  if (!a.gpu_shadows.is_none()) o.gpu_shadows = string_arg(a.gpu_shadows, "gpu_shadows");
  if (!a.gpu_max_views.is_none()) o.gpu_max_views = int_arg(a.gpu_max_views, "gpu_max_views");
  if (!a.gpu_shading.is_none()) o.gpu_shading = string_arg(a.gpu_shading, "gpu_shading");
  return o;
}

// A misspelt keyword is a bad argument (SceneError naming it), not a TypeError.
void reject_unknown_keywords(const py::kwargs& unknown) {
  if (unknown.empty()) return;
  const std::string name = py::str(unknown.begin()->first);
  throw InputError("render: unknown keyword '" + name +
                   "' (method, cube_res, max_depth, camera, aovs, stats, timeout, reference, "
                   "threads, search, refine, theta_max_deg, refraction, envmap_lookup, "
                   "error_target, fresnel, max_layers, max_memory_mib, max_pixels, "
                   "plan_everything, reference_image, resolve, side_structure, gpu_mirrors, "
                   "gpu_shadows, gpu_max_views, gpu_shading)");
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
py::object render(Renderer& renderer, const py::handle& scene_object, const RenderArgs& args) {
  if (!py::isinstance<Scene>(scene_object)) {
    throw InputError("scene: must be an abcube.Scene (load_scene, scene_from_dict), got " +
                     type_name(scene_object));
  }
  const Scene scene = scene_object.cast<Scene>();  // a cheap copy sharing the loaded data
  const RenderOptions options = options_from_args(args);
  const bool want_result = !args.aovs.is_none() || options.stats;
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
  if (!want_result) return image_to_array(std::move(result.image));

  // The image, the AOVs and the stats as Python objects.
  PyRenderResult out;
  out.image = image_to_array(std::move(result.image));
  for (auto& [name, image] : result.aovs) out.aovs[py::str(name)] = image_to_array(std::move(image));
  out.stats = result.stats.json.empty()
                  ? py::object(py::none())
                  : py::module_::import("json").attr("loads")(result.stats.json);
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

constexpr const char* RENDER_DOC = R"doc(Renders `scene` and returns its image.

Returns a float32 array H x W x 3 (linear RGB, row 0 at the top), identical to the float
EXR `abcube render` writes for the same inputs. With `aovs` (a list of "distance",
"normal", "object_id", "fallback") or stats=True it returns a RenderResult instead:
.image, .aovs (name -> float32 H x W, H x W x 3 for "normal"), .stats (the CLI's --stats
JSON as a dict, or None).

Arguments left None take the scene's own value: method (abuffer | zbuffer | envmap |
raytrace | gpu | hybrid), cube_res (texels per cube face edge), max_depth (bounces), camera (a dict
with any of position, look_at, up, fov_y, width, height; only the keys given change),
error_target, fresnel. timeout: seconds, RenderTimeout (a RuntimeError) past it.
reference: also trace the exact image, error figures in the stats. The other keywords are
the CLI's options by their RenderOptions names: search (crossing | thesis), refine (mesh |
plane), theta_max_deg, refraction (search | thick_lens | thin_lens), envmap_lookup (R |
bisector | position), max_layers, max_memory_mib, max_pixels, plan_everything,
reference_image, resolve (exact | thesis: intersecting fragments by per-sample priority
masks or by the thesis' Vis_front estimate), side_structure (default True; False is the
CLI's --map-only: searches see only the map, no side structure for the triangles it cannot
hold); and for gpu and hybrid: gpu_mirrors (stencil | envmap), gpu_shadows (volumes | maps),
gpu_max_views, gpu_shading (pixels | samples: the camera pass's colour shaded once a pixel
and surface or once a sample).

A bad argument or scene raises SceneError (a ValueError) naming it; other failures
RuntimeError. The GIL is released while the render runs (see Renderer). Ctrl-C (SIGINT,
with Python's default handler) stops a render called from the main thread at its next
check and raises KeyboardInterrupt.)doc";

}  // namespace

void bind_renderer(py::module_& m) {
  py::class_<PyRenderResult>(m, "RenderResult",
                             "What Renderer.render returns when aovs or stats are asked for.")
      .def_readonly("image", &PyRenderResult::image, "float32 H x W x 3, linear RGB.")
      .def_readonly("aovs", &PyRenderResult::aovs,
                    "dict name -> float32 H x W (H x W x 3 for \"normal\").")
      .def_readonly("stats", &PyRenderResult::stats,
                    "dict: the CLI's --stats JSON (plan, timings_ms, counts, memory, GL path), "
                    "or None without stats=True.")
      .def("__repr__", [](const PyRenderResult& r) {
        return "<abcube.RenderResult image " + std::string(py::str(r.image.attr("shape"))) +
               ", aovs " + std::string(py::str(py::list(r.aovs))) + ", stats " +
               (r.stats.is_none() ? "None" : "{...}") + ">";
      });

  py::class_<Renderer>(m, "Renderer", RENDERER_DOC)
      .def(py::init(&make_renderer), py::arg("gl") = "auto", py::arg("threads") = 0,
           py::arg("gl_device") = -1)
      .def(
          "render",
          [](Renderer& self, const py::object& scene, const py::object& method,
             const py::object& cube_res, const py::object& max_depth, const py::object& camera,
             const py::object& aovs, const py::object& stats, const py::object& timeout,
             const py::object& reference, const py::object& threads, const py::object& search,
             const py::object& refine, const py::object& theta_max_deg,
             const py::object& refraction, const py::object& envmap_lookup,
             const py::object& error_target, const py::object& fresnel,
             const py::object& max_layers, const py::object& max_memory_mib,
             const py::object& max_pixels, const py::object& plan_everything,
             const py::object& reference_image, const py::object& resolve,
             const py::object& side_structure, const py::object& gpu_mirrors,
             const py::object& gpu_shadows, const py::object& gpu_max_views,
             const py::object& gpu_shading, const py::kwargs& unknown) {
            reject_unknown_keywords(unknown);
            return render(self, scene,
                          RenderArgs{method, cube_res, max_depth, camera, aovs, stats, timeout,
                                     reference, threads, search, refine, theta_max_deg,
                                     refraction, envmap_lookup, error_target, fresnel,
                                     max_layers, max_memory_mib, max_pixels, plan_everything,
                                     reference_image, resolve, side_structure, gpu_mirrors,
                                     gpu_shadows, gpu_max_views, gpu_shading});
          },
          py::arg("scene"), py::kw_only(), py::arg("method") = py::none(),
          py::arg("cube_res") = py::none(), py::arg("max_depth") = py::none(),
          py::arg("camera") = py::none(), py::arg("aovs") = py::none(),
          py::arg("stats") = false, py::arg("timeout") = py::none(),
          py::arg("reference") = false, py::arg("threads") = py::none(),
          py::arg("search") = py::none(), py::arg("refine") = py::none(),
          py::arg("theta_max_deg") = py::none(), py::arg("refraction") = py::none(),
          py::arg("envmap_lookup") = py::none(), py::arg("error_target") = py::none(),
          py::arg("fresnel") = py::none(), py::arg("max_layers") = py::none(),
          py::arg("max_memory_mib") = py::none(), py::arg("max_pixels") = py::none(),
          py::arg("plan_everything") = false, py::arg("reference_image") = py::none(),
          py::arg("resolve") = py::none(), py::arg("side_structure") = py::none(),
          py::arg("gpu_mirrors") = py::none(), py::arg("gpu_shadows") = py::none(),
          py::arg("gpu_max_views") = py::none(), py::arg("gpu_shading") = py::none(),
          RENDER_DOC)
      .def_property_readonly("gl_path", &Renderer::gl_path,
                             "The GL path opened (\"\" before the first GL render; \"none\" "
                             "when GL was not wanted or not found under auto).")
      .def_property_readonly("gl_renderer", &Renderer::gl_renderer, "GL_RENDERER of that path.")
      .def_property_readonly("renders", &Renderer::renders, "Renders done so far.");
}

}  // namespace abcube
