// What the GL techniques (host/gl/) and the users of their front, GlScene (gl_passes.hpp),
// share: how the scene is given to the GL, the passes' timings, the camera pass's options
// and what it reports, the values a texel holds where no surface is, and the limits of the
// current context. Beneath the front, so that a technique needs no part of it.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>

#include "gl/glsl_shared.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// Wall milliseconds of GL work (glFinish-bracketed) and of reading it back.
struct GpuTimings {
  double upload_ms = 0;  // triangles and materials uploaded, shaders compiled
  double cube_distance_ms = 0;
  double cube_color_ms = 0;
  double camera_ms = 0;
  double readback_ms = 0;
  double shadow_maps_ms = 0;
  double environment_ms = 0;
};

// Shadow bias of the GPU cube shadow maps, in texels (common_shading.glsl).
constexpr double SHADOW_BIAS_TEXELS = 1.5;
// Layers of the camera view peeled when a material has coverage transparency (opacity
// < 1), at most; behind the last, the background shows through what is left.
constexpr int MAX_CAMERA_LAYERS = 16;

// Where the camera pass samples each pixel: its centre (one sample, aliased), or the
// A-buffer's 4x8 sample positions (samples.hpp), box-filtered as the CPU resolve weighs
// its masks.
enum class CameraSamples { pixel_centre, mask_4x8 };

// What the camera pass renders exactly where the GPU can (gl_camera_exact.cpp;
// docs/design/gl-camera-exact.md): planar mirrors by virtual objects and the stencil test
// (course notes 4.1.2; Kilgard 1999), recursively to max_depth; hard shadows of opaque
// blockers by shadow volumes counted depth-fail (course notes 3.3; Everitt & Kilgard 2002).
// What it cannot (curved mirrors, refraction, coverage transparency, more than
// MAX_VOLUME_LIGHTS lights) keeps the cube maps: the environment map and the shadow maps.
struct ExactCameraOptions {
  bool planar_mirrors = false;  // stencil portals for planar_reflectors.hpp's mirrors
  bool shadow_volumes = false;  // shadow volumes for the shadow-casting lights
  int max_depth = 0;            // mirror bounces, as render.max_depth
  // Mirror views drawn per camera tile, at most; a mirror seen past that falls back to the
  // environment map (and is counted).
  int max_views = 256;
  // Use the exact pass even with no planar mirror and no volume light (the hybrid method
  // reads its per-pixel flags).
  bool always = false;
  // How the colour of a view is shaded (gl_shading_groups.cpp): once a pixel and surface (the
  // samples grouped by triangle and shadow-volume set, camera_groups.frag), or once a sample
  // (camera_exact.frag).
  enum class Shading { pixels, samples } shading = Shading::pixels;
};
// What the last exact camera pass says of each pixel: 1 when none of its 32 samples met a
// surface the GPU only approximates (camera_exact.frag's alpha), 0 otherwise (the hybrid
// method redoes those on the CPU).
struct ExactCameraStats {
  bool mirrors = false, volumes = false;  // what the last camera pass used
  bool plain = false;                     // the exact pass ran without either (ExactCameraOptions::always)
  std::string mirrors_why, volumes_why;   // why not, when asked but not used
  size_t reflectors = 0;                  // planar reflectors in the scene
  uint64_t curved_reflective_triangles = 0;
  uint64_t mirror_views = 0;              // virtual views drawn (every tile, every level)
  uint64_t mirror_views_empty = 0;        // mirrors drawn but covering no sample
  uint64_t mirror_views_over_budget = 0;  // mirrors shown through the environment map instead
  int deepest_level = 0;
  uint64_t samples_approximate = 0;  // camera samples whose path meets an approximated surface
  uint64_t pixels_exact = 0;         // pixels with none
  int volume_lights = 0;
  uint64_t volume_triangles = 0;  // over every volume light
  bool shading_pixels = false;    // the colour shaded once a pixel and surface (else once a sample)
  std::string shading_why;        // why per sample, when pixels were asked
  double volume_build_ms = 0;
};

// Value of a prepass texel that no surface covers.
constexpr float NO_DISTANCE = INFINITY;
constexpr uint32_t NO_OBJECT = 0xffffffffu;

// Refuses (InputError naming the count and the limit) a scene the current GL context cannot
// draw under the gpu method: more shadow-casting lights than a cube-map array of shadow
// maps holds (GL_MAX_ARRAY_TEXTURE_LAYERS / 6: 341 on llvmpipe, 341 or 2730 on NVIDIA).
void check_gl_limits(const SceneData& scene);
// That limit: shadow-casting lights the current GL context holds for the gpu method.
int gl_shadow_light_limit();

// How GlScene gives the GL the soup (both off: as a GL without the features gets it).
struct GlSceneOptions {
  // The buffers over the soup's own memory where the GL can (GL_AMD_pinned_memory); false
  // copies them, as every GL without the extension does.
  bool pin_soup = true;
  // Each triangle's ids read by the vertex stage from the soup's per-triangle arrays where
  // the GL allows (triangle_ids.glsl); false gives every vertex its ids as attributes.
  bool triangle_ids = true;
};

}  // namespace abcube
