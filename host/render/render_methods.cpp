#include "render/render_methods.hpp"

#include <cmath>
#include <memory>
#include <optional>

#include <abcube/image.hpp>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_passes.hpp"
#include "io/metrics.hpp"
#include "raster/edge_ties.hpp"
#include "base/samples.hpp"
#include "reference/raytrace.hpp"
#include "render/crosscheck.hpp"
#include "render/stats_json.hpp"
#include "render/target_db.hpp"
#include "scene/plan.hpp"

namespace abcube {

using nlohmann::json;

// A pass of the render starts (0) or ends (1), for the progress callback when there is one.
void pass_progress(const MethodContext& mc, const char* pass, double done) {
  if (mc.progress) mc.progress(pass, done);
}

void read_gpu_options(const RenderOptions& o, int max_depth, RenderRequest* r) {
  r->gpu.planar_mirrors = o.gpu_mirrors == "stencil";
  r->gpu.shadow_volumes = o.gpu_shadows == "volumes";
  r->gpu.max_views = o.gpu_max_views;
  r->gpu.shading =
      o.gpu_shading == "pixels" ? ExactCameraOptions::Shading::pixels : ExactCameraOptions::Shading::samples;
  r->gpu.max_depth = max_depth;
}

namespace {

RenderRequest::SearchOn read_where(const std::string& name) {
  using SearchOn = RenderRequest::SearchOn;
  return name == "gpu" ? SearchOn::gpu : name == "cpu" ? SearchOn::cpu : SearchOn::automatic;
}

}  // namespace

void read_search_on(const RenderOptions& o, RenderRequest* r) { r->search_on = read_where(o.search_on); }

void read_resolve_on(const RenderOptions& o, RenderRequest* r) { r->resolve_on = read_where(o.resolve_on); }

std::vector<std::string> gpu_camera_option_keys() {
  return {"gpu_mirrors", "gpu_shadows", "gpu_max_views", "gpu_shading"};
}

json gl_json(const GlContext& ctx) {
  const GlInfo& i = ctx.info();
  json j = {{"gl_version", i.gl_version}, {"gl_vendor", i.gl_vendor}};
  if (!i.egl_vendor.empty()) j["egl_vendor"] = i.egl_vendor;
  if (i.device_index >= 0) j["egl_device"] = i.device_index;
  return j;
}

// What the exact camera pass rendered: per kind of surface, the path it took and why.
// `curved`: what curved mirrors and refraction took; `maps`: shadow maps were built.
json gpu_paths_json(const GlScene& gl, const RenderRequest& request, const std::string& curved, bool maps) {
  const ExactCameraStats& ex = gl.exact_camera_stats();
  return {
      {"planar_mirrors",
       {{"technique", ex.mirrors ? "stencil" : curved},
        {"why", ex.mirrors                   ? "exact: virtual views through the stencil test, to max_depth"
                : request.gpu.planar_mirrors ? ex.mirrors_why
                                             : "asked: --gpu-mirrors envmap"},
        {"reflectors", ex.reflectors},
        {"views", ex.mirror_views},
        {"views_empty", ex.mirror_views_empty},
        {"views_over_budget", ex.mirror_views_over_budget},
        {"max_views_per_tile", request.gpu.max_views},
        {"deepest_level", ex.deepest_level}}},
      {"curved_mirrors_and_refraction",
       {{"technique", curved},
        {"curved_reflective_triangles", ex.curved_reflective_triangles},
        {"why", curved == "environment_map" ? "approximate: Blinn-Newell lookups in the cube texture around the eye"
                : curved == "none"          ? "none in the view's reach (or max_depth 0)"
                                            : "the CPU's A-buffer searches, for the pixels they reach"}}},
      {"shadows",
       {{"technique", ex.volumes ? "shadow_volumes"
                      : maps     ? "shadow_maps"
                                 : "none"},
        {"why", ex.volumes                   ? "exact: depth-fail counting of every opaque blocker's prism"
                : request.gpu.shadow_volumes ? ex.volumes_why
                                             : "asked: --gpu-shadows maps"},
        {"volume_lights", ex.volumes ? ex.volume_lights : 0},
        {"volume_triangles", ex.volumes ? ex.volume_triangles : 0},
        {"translucent_casters", maps && gl.shadow_peels() > 0 ? "shadow maps' peeled layers" : "none"}}},
      {"shading",
       {{"technique", ex.shading_pixels ? "pixels" : "samples"},
        {"why", ex.shading_pixels ? "once a pixel and surface: its samples grouped by triangle and shadow-volume set"
                                  : ex.shading_why}}},
      {"camera_samples_approximate", ex.samples_approximate},
      {"pixels_exact", ex.pixels_exact}};
}

Image render_reference(MethodContext& mc, const char* key) {
  RaytraceOptions options;
  options.threads = mc.request.threads;
  // The raytrace method at its rung of THE SAMPLE LADDER; the reference of the other methods
  // always at all 32.
  if (std::string(key) == "raytrace") {
    if (mc.scene.render.target_db > 0) return raytrace_for_target(mc);
    options.samples_per_pixel = mc.scene.render.samples;
    mc.stats["counts"]["camera_samples_per_pixel"] = options.samples_per_pixel;
    mc.stats["method_options"]["samples"] = options.samples_per_pixel;
  }
  if (mc.progress) {
    const std::string stage = key;
    options.progress = [&mc, stage](double done) { mc.progress(stage, done); };
  }
  options.bvh = mc.cache.bvh();
  RaytraceStats rs;
  Image image = render_raytrace(mc.scene, options, &rs);
  mc.stats[key].update(raytrace_json(rs));  // beside what the map method put there (ray_error)
  mc.record.tracer_timings_ms[key] = tracer_timings(rs);
  return image;
}

double add_reference_error(MethodContext& mc, const Image& image) {
  json& stats = mc.stats;
  const RenderRequest& r = mc.request;
  Image ref;
  if (!r.reference_image.empty()) {
    ref = read_image(r.reference_image);
    if (ref.width != image.width || ref.height != image.height) {
      throw InputError(r.reference_image + ": is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                       ", the render is " + std::to_string(image.width) + "x" + std::to_string(image.height));
    }
    stats["reference"]["image"] = r.reference_image;
  } else {
    // The tracer's own image is the reference only at the reference's 32 samples.
    const bool reference_itself = mc.scene.render.method == "raytrace" && mc.scene.render.target_db <= 0 &&
                                  mc.scene.render.samples == MASK_SAMPLES;
    ref = reference_itself ? image : render_reference(mc, "reference");
  }
  const ImageError e = image_error(image, ref);
  stats["reference"]["image_error"] = image_error_json(e);
  if (!stats["reference"].contains("ray_error")) {
    stats["reference"]["ray_error"] =
        "n/a: method " + mc.scene.render.method + " does no map search (Error_CP and Error_Parallax measure searches)";
  }
  return e.psnr;
}

}  // namespace abcube
