// The GL passes over one uploaded scene (GlScene): the six cube faces around a centre
// (distance prepass, Z-buffer colour, the environment map), the cube shadow maps with their
// translucent peels, and the camera view: Z-buffer Phong, or the exact camera pass (planar
// mirrors by the stencil, shadow volumes, the colour shaded once a pixel and surface) with its
// per-pixel flags for the hybrid method. Each technique is a unit of its own under host/gl/;
// GlScene is their front, and what they share with its users is in gl_types.hpp. Results
// are read back into cpu_core image types.
#pragma once
#include <glad/gl.h>

#include <memory>
#include <vector>

#include "gl/gl_program.hpp"
#include "gl/gl_types.hpp"
#include "io/image.hpp"
#include "gpu_geometry/planar_reflectors.hpp"
#include "scene/scene_data.hpp"
#include "shading/map_shading.hpp"

namespace abcube {

class GlABufferBuilder;
class GlResolvePlanner;
class GlExactCamera;
struct GlSceneParts;

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

  // The A-buffers' compute passes (gl_abuffer.hpp), compiled on first use and kept with the
  // scene, so that the renders of one upload compile them once.
  const GlABufferBuilder& abuffer_builder();
  // THE RESOLVE PLAN's compute pass (gl_resolve_plan.hpp), kept the same way.
  const GlResolvePlanner& resolve_planner();
  // The techniques' shared parts, for the passes outside this class (gl_shadow_probe.hpp).
  GlSceneParts& parts() { return *parts_; }

 private:
  std::unique_ptr<GlSceneParts> parts_;
  std::unique_ptr<GlExactCamera> exact_;
  std::unique_ptr<GlABufferBuilder> abuffer_;
  std::unique_ptr<GlResolvePlanner> resolve_planner_;
  int camera_layers_ = 0;
  bool camera_layers_capped_ = false;
};

}  // namespace abcube
