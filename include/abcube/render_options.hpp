// What a render is asked for, as plain data: RenderOptions (one render), CameraOverride (its
// camera's changes) and RendererOptions (a Renderer's GL and threads). The Renderer that
// takes them: <abcube/renderer.hpp>; the option table that fills them from a command line,
// a batch job or Python keywords: <abcube/options.hpp>.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace abcube {

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
  std::string method;                       // a registered method (method_names(): abuffer, ...) ("" = render.method)
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
  std::string shading_points = "quarters";  // per camera fragment: quarters (adaptive, 2 to 4) | sparse | one
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
  std::string search_on = "auto";       // gpu_abuffer, hybrid: map searches on auto (hardware GL) | gpu | cpu
  std::string resolve_on = "auto";      // gpu_abuffer, hybrid: the resolve planned on auto (hardware GL) | gpu | cpu
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

struct RendererOptions {
  std::string gl = "auto";  // auto | egl | egl-device | egl-surfaceless | osmesa | none
  int gl_device = -1;       // EGL device index (-1: ABCUBE_EGL_DEVICE, else the first hardware one)
  int threads = 0;          // worker threads per render (0 = every core)
};

}  // namespace abcube
