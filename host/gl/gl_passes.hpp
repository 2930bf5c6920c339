// The GL passes over one uploaded scene (GlScene): the six cube faces around a centre
// (distance prepass, Z-buffer colour, the environment map), the cube shadow maps with their
// translucent peels, and the camera view: Z-buffer Phong, or the exact camera pass (planar
// mirrors by the stencil, shadow volumes, the colour shaded once a pixel and surface) with its
// per-pixel flags for the hybrid method. Each technique is a unit of its own under host/gl/;
// GlScene is their front. Results are read back into cpu_core image types.
#pragma once
#include <glad/gl.h>

#include <memory>
#include <vector>

#include "gl/gl_program.hpp"
#include "gl/glsl_shared.hpp"
#include "io/image.hpp"
#include "gpu_geometry/planar_reflectors.hpp"
#include "scene/scene_data.hpp"
#include "shading/map_shading.hpp"

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

class GlExactCamera;
struct GlSceneParts;

// How GlScene gives the GL the soup (both off: as a GL without the features gets it).
struct GlSceneOptions {
  // The buffers over the soup's own memory where the GL can (GL_AMD_pinned_memory); false
  // copies them, as every GL without the extension does.
  bool pin_soup = true;
  // Each triangle's ids read by the vertex stage from the soup's per-triangle arrays where
  // the GL allows (triangle_ids.glsl); false gives every vertex its ids as attributes.
  bool triangle_ids = true;
};

// The scene uploaded to the current GL context, and the passes over it: a small front over
// one unit per technique (gl_scene_parts.hpp lists them). Needs a current GL 4.5 context for
// its whole life (gl_context.hpp).
class GlScene {
 public:
  explicit GlScene(const SceneData& scene, const GlSceneOptions& options = {});
  ~GlScene();
  GlScene(const GlScene&) = delete;
  GlScene& operator=(const GlScene&) = delete;

  // Distance prepass over the six faces around `center` (gl_cube_passes.cpp): per texel the
  // Euclidean distance to the nearest surface (NO_DISTANCE where none) and its object id
  // (NO_OBJECT), faces as cube_map.hpp defines them. `ids` may be null. Faces of n_s x n_t
  // texels; n_t = 0 means square (a 8x, 4x supersampled face checks the 4x8 sample positions).
  void cube_distance(const glm::dvec3& center, int n, CubeImage* distance, CubeIds* ids, int n_t = 0);

  // Z-buffer Phong colour of the six faces seen from `center` (no shadows).
  CubeImage cube_color(const glm::dvec3& center, int n);

  // Z-buffer Phong image of the camera view, sampled at `samples` (gl_camera_pass.cpp). Uses
  // the shadow maps and the environment map when they have been built. mask_4x8 renders the
  // view at 8x the columns and 4x the rows, in tiles, and averages each pixel's 32 samples;
  // it is the exact camera pass (gl_camera_exact.cpp) where set_exact_camera asks for it and
  // it applies.
  Image camera_color(const Camera& camera, CameraSamples samples = CameraSamples::pixel_centre);

  // The object id the Z-buffer sees at each of the camera's 4x8 samples per pixel
  // (samples.hpp): (8 width) x (4 height) values, row 0 at the top, NO_OBJECT where none.
  // Pixel (x, y), sample k is at row 4 y + k / 8, column 8 x + k % 8.
  std::vector<uint32_t> camera_objects(const Camera& camera);

  // One cube shadow map per light with cast_shadows, at n x n per face (gl_shadow_maps.hpp);
  // later colour passes are shadowed by them. Returns how many lights. Maps of the same
  // size built before are kept.
  int build_shadow_maps(int n);
  // Translucent layers the last build_shadow_maps peeled (0: no translucent caster), and
  // whether crossings were left beyond MAX_SHADOW_PEELS.
  int shadow_peels() const;
  bool shadow_peels_capped() const;
  // Layers the last camera_color drew (1 without coverage transparency), and whether
  // samples were left beyond MAX_CAMERA_LAYERS.
  int camera_layers() const { return camera_layers_; }
  bool camera_layers_capped() const { return camera_layers_capped_; }

  // The Z-buffer colour of the six faces around `center` (with shadows if built) kept on
  // the GPU as a cube texture (gl_environment.hpp); later camera passes look it up for kr
  // and kt.
  void build_environment(const glm::dvec3& center, int n);
  // Later camera passes look up no environment (max_depth 0, or nothing reflects).
  void drop_environment();
  // How later camera passes look the environment up: the envmap method's lookup direction
  // (R, bisector, position) and Schlick's weights for kr and kt (shading.hpp).
  void set_environment_lookup(EnvmapLookup lookup, bool fresnel);

  // The exact camera pass (ExactCameraOptions): later camera_color calls use it where it
  // applies; exact_camera_stats() says what the last one did.
  void set_exact_camera(const ExactCameraOptions& options);
  const ExactCameraStats& exact_camera_stats() const;
  // Whether the next mask_4x8 camera pass would be the exact one (the options set, the
  // scene, this GL); exact_camera_stats() then says why not.
  bool exact_camera_possible();
  const PlanarReflectors& planar_reflectors() const;
  const std::vector<uint8_t>& exact_pixels() const;

  // Textures sampled at level 0 with zero derivatives (bilinear), as the CPU's point
  // samples, instead of trilinear over the pass's footprint: `abcube crosscheck` compares
  // the lookups, not the two filters.
  void set_texture_level0(bool on);

  const GpuTimings& timings() const;
  // Whether the vertex buffers are the soup's own memory (GL_AMD_pinned_memory), not a copy.
  bool soup_pinned() const;
  // Whether the vertex stage reads each triangle's ids from the soup's arrays (triangle_ids.glsl).
  bool triangle_ids() const;
  double near_distance() const;
  int max_size() const;

  // The techniques' shared parts, for the passes outside this class (gl_shadow_probe.hpp).
  GlSceneParts& parts() { return *parts_; }

 private:
  std::unique_ptr<GlSceneParts> parts_;
  std::unique_ptr<GlExactCamera> exact_;
  int camera_layers_ = 0;
  bool camera_layers_capped_ = false;
};

}  // namespace abcube
