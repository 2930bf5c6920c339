// abcube's library API: render a Scene into an Image in memory (the CLI, `abcube batch`,
// the Python module and the tests are all clients of this one call).
//
//   abcube::Scene scene = abcube::Scene::load("scenes/cornell.json");
//   abcube::Renderer renderer;                        // GL opened on first need
//   abcube::RenderOptions options;
//   options.camera.position = {0, 1, -3};             // only the keys given change
//   abcube::RenderResult r = renderer.render(scene, options);
//   abcube::write_image("view.exr", r.image);
//
// THREADS. One Renderer belongs to one thread at a time: render() on one Renderer is
// serialized (a second caller waits for the first). Several Renderers may render at once
// from several threads, the same Scene or different ones (Scenes are immutable and shared).
// Each Renderer that needs GL opens its own context on its own thread's first GL render;
// render() must then be called from that same thread (GL contexts are current per thread),
// or a RuntimeFailure says so.
//
// ERRORS. Bad input (an option, a camera, a scene) throws InputError with one line naming
// the option; other failures RuntimeFailure (RenderTimeout past options.timeout_s); a
// failed internal check InternalError. Nothing exits or aborts the process.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <abcube/error.hpp>
#include <abcube/image.hpp>
#include <abcube/scene.hpp>

namespace abcube {

// "abcube X.Y.Z" (and " (git COMMIT)" when built from a git checkout).
std::string version_string();

// Asks every render of the process to stop at its next check (before each tile, row or
// pass: the checks of RenderOptions::timeout_s): each throws Interrupted(signal), and an
// image being written is not put in place (its temporary is removed). Async-signal-safe:
// made for a SIGINT or SIGTERM handler (the CLI's, docs/robustness.md). Renders
// started later stop at once too, until clear_stop_request().
void request_stop(int signal);
void clear_stop_request();
bool stop_requested();

// Replaces only the keys given; the rest come from the scene's camera. Validated as the
// scene file's camera is (fov_y in (0, 180) degrees, sizes >= 1, up not along the view).
struct CameraOverride {
  std::optional<std::array<double, 3>> position, look_at, up;
  std::optional<double> fov_y;       // degrees
  std::optional<int> width, height;  // pixels
};

// The names the string options accept (the CLI's --help and the messages list them too).
// Empty strings and negative numbers mean "the scene's own value".
struct RenderOptions {
  std::string method;                       // abuffer | zbuffer | envmap | raytrace | gpu | hybrid ("" = render.method)
  int cube_resolution = 0;                  // N texels per face edge (0 = render.cube_resolution, or error_target's)
  int max_depth = -1;                       // bounces (< 0 = render.max_depth)
  double error_target = -1;                 // > 0: N from the Error_Parallax bound 1/(2 N^2) (< 0 = the scene's)
  double target_db = -1;                    // > 0: the PSNR to reach against the tracer: abuffer picks N, raytrace
                                            // its samples (< 0 = the scene's)
  int samples = 0;                          // raytrace: camera samples a pixel, 1, 2, 4, 8, 16 or 32 (0 = the scene's)
  std::optional<bool> fresnel;              // Schlick weights for kr and kt (unset = the scene's)
  int threads = 0;                          // 0 = the Renderer's (RendererOptions::threads)
  bool reference = false;                   // also trace the exact reference: error figures in the stats
  std::string reference_image;              // the exact image rendered before (implies reference)
  bool plan_everything = false;             // run the steps the plan would skip, to time them
  std::string search = "crossing";          // crossing | thesis (map searches, thesis 7.4)
  std::string refine = "mesh";              // mesh | plane (crossing refinement)
  double theta_max_deg = 2.0;               // thesis mode's acceptance angle, degrees
  std::string refraction = "search";        // search | thick_lens | thin_lens
  std::string envmap_lookup = "R";          // R | bisector | position (envmap method)
  std::string shading_points = "quarters";  // per camera fragment: quarters (adaptive, 2 to 4) | one | sparse
  std::string texture_lookups = "samples";  // a textured fragment's base colour: samples (averaged) | points
  std::string shadow_edges = "samples";     // a shadow edge inside a fragment: samples (each its own) | points
  std::string secondary_edges = "samples";  // reflections and refractions inside a fragment: samples | points
  std::string resolve = "exact";            // intersecting fragments: exact (priority masks) | thesis (Vis_front)
  bool side_structure = true;               // searches also test the triangles the map cannot hold (false: --map-only)
  std::string gpu_mirrors =
      "stencil";  // gpu: planar mirrors by the stencil test | envmap (every mirror from the cube texture)
  std::string gpu_shadows = "volumes";  // gpu: shadow volumes | maps (cube shadow maps)
  int gpu_max_views = 256;              // gpu: mirror views drawn per camera tile, at most
  std::string gpu_shading = "pixels";   // gpu: shade once a pixel and surface | once a sample
  uint32_t max_layers = 0;              // A-buffer layers kept per list (0 = all)
  uint64_t max_memory_mib = 0;          // the whole render's memory budget, MiB (0 = the memory available)
  uint64_t max_pixels = 0;              // refuse a camera image larger than this (0 = no cap)
  CameraOverride camera;
  // Extra per-pixel outputs, each an Image in RenderResult::aovs, from the eye ray through
  // the pixel centre (the exact tracer on the same triangles, whatever the method):
  // "distance" (1 channel, world units from the camera to the first surface, +inf where
  // none), "normal" (3 channels, unit shading normal facing the camera, 0 where none),
  // "object_id" (1 channel, the object's index in the file, -1 where none; exact in float
  // up to 2^24 objects), "shadowed" (1 channel, the share of the scene's lights whose light
  // that surface does not get whole, 0 where none); and from the render itself,
  // "fallback" (1 channel, map methods: the share of the pixel's secondary searches that
  // found nothing: a reflection or refraction-exit miss, a shadow walk on a zero-area
  // surface or aborted, a lens transfer that fell back to a search; 0 where none was made
  // and for the other methods).
  std::vector<std::string> aovs;
  bool stats = true;     // fill RenderResult::stats (cheap; off saves its JSON)
  double timeout_s = 0;  // > 0: stop with RenderTimeout past this many seconds
  // Called on the rendering thread with a stage name and the share done, in [0, 1].
  std::function<void(const std::string& stage, double done)> progress;
};

// What a render reports: its JSON form is the CLI's --stats file (plan, per-pass
// milliseconds, counts, memory, the GL path, error figures with reference).
struct RenderStats {
  double total_ms = 0;
  // Per pass; the exact tracer's as "raytrace.trace", "reference.bvh_build", ...; no
  // scene loading (Scene::load_ms; the CLI adds it as "load").
  std::map<std::string, double> timings_ms;
  std::string gl_path;  // "egl-surfaceless", "osmesa", ... or "none"
  std::string gl_renderer;
  // Per-scene data built by THIS render (0 when an earlier render of the scene built it):
  // the searches' mesh neighbours, the lens fits, the tracer's BVH.
  int scene_data_built = 0;
  std::optional<double> psnr_db;  // with reference: the image against the exact one
  std::string json;               // everything, as a JSON object (2-space indent)
};

struct RenderResult {
  Image image;                        // linear RGB, height x width
  std::map<std::string, Image> aovs;  // as asked in RenderOptions::aovs
  RenderStats stats;
};

// What each method honours (docs/methods.md): throws OptionError (an InputError) with one
// line when `options` gives a setting that the render's method (options.method, or the
// scene's) has no use for, e.g. refraction "thick_lens" with raytrace; the methods each
// option serves are in the option table (<abcube/options.hpp>). `abcube render`, `abcube
// batch` and the Python module call it before rendering; Renderer::render itself leaves
// such settings unused, so that one RenderOptions can serve renders of several methods.
// The scene file's own settings (render.cube_resolution, ...) are every method's defaults
// and never refused.
void refuse_unused_options(const Scene& scene, const RenderOptions& options);

struct RendererOptions {
  std::string gl = "auto";  // auto | egl | egl-device | egl-surfaceless | osmesa | none
  int gl_device = -1;       // EGL device index (-1: ABCUBE_EGL_DEVICE, else the first hardware one)
  int threads = 0;          // worker threads per render (0 = every core)
};

class Renderer {
 public:
  explicit Renderer(const RendererOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  RenderResult render(const Scene& scene, const RenderOptions& options = {});

  // The GL path this Renderer opened ("" before its first GL render; "none" when GL was
  // not wanted or not found under auto) and its GL_RENDERER string.
  std::string gl_path() const;
  std::string gl_renderer() const;
  uint64_t renders() const;  // renders done so far

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace abcube
