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
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <abcube/error.hpp>
#include <abcube/image.hpp>
#include <abcube/render_options.hpp>
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

// The registered render methods' names, built-ins first: the values of --method,
// render.method and method=.
std::vector<std::string> method_names();

// The methods that read the option `key` (the table's key): for a per-method option those
// whose unit lists it; empty for an option every method reads.
std::vector<std::string> methods_reading(const std::string& key);

// What each method honours (docs/methods.md): throws OptionError (an InputError) with one
// line when `options` gives a setting that the render's method (options.method, or the
// scene's) does not read, e.g. refraction "thick_lens" with raytrace, naming the methods
// that read it; for a method name no method has; and for search_on "gpu" with the thesis
// mode, which the GPU's searches do not take. `abcube render`, `abcube batch` and the
// Python module call it before rendering; Renderer::render itself leaves such settings
// unused, so that one RenderOptions can serve renders of several methods. The scene file's
// own settings (render.cube_resolution, ...) are every method's defaults and never refused.
void refuse_unused_options(const Scene& scene, const RenderOptions& options);
// The same for a scene whose render.method is `scene_method`.
void refuse_options_unused_by(const std::string& scene_method, const RenderOptions& options);

// `options` for a render by `method`: the method set, and every option that method does
// not read back at its default (one set of options for renders of several methods, as
// `abcube report` makes them).
RenderOptions without_unused_options(const RenderOptions& options, const std::string& method);

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
