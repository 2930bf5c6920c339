// The GL passes over one uploaded scene (GlScene): the six cube faces around a centre
// (distance prepass, Z-buffer colour, the environment map: gl_environment.cpp), the cube
// shadow maps with their translucent peels (gl_shadow_maps.cpp), and the camera view: Z-buffer
// Phong, or the exact camera pass (planar mirrors by the stencil, gl_camera_exact.cpp; shadow
// volumes, gl_shadow_volumes.cpp; the colour shaded once a pixel and surface,
// gl_shading_groups.cpp) with its per-pixel flags for the hybrid method; and crosscheck's
// probes (camera objects; shadow probe, gl_shadow_volumes.cpp). The upload, the draw calls and
// the other passes are gl_passes.cpp's. Results are read back into cpu_core image types.
#pragma once
#include <glad/gl.h>

#include <memory>
#include <vector>

#include "gl/gl_program.hpp"
#include "io/image.hpp"
#include "gpu_geometry/planar_reflectors.hpp"
#include "scene/scene_data.hpp"
#include "gpu_geometry/shadow_volume.hpp"
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
// Translucent shadow casters peeled per light, at most (shadow_caster.frag; the GLSL
// constant of the same name). Crossings beyond the last layer let the light through.
constexpr int MAX_SHADOW_PEELS = 8;
// Layers of the camera view peeled when a material has coverage transparency (opacity
// < 1), at most; behind the last, the background shows through what is left.
constexpr int MAX_CAMERA_LAYERS = 16;

// Where the camera pass samples each pixel: its centre (one sample, aliased), or the
// A-buffer's 4x8 sample positions (samples.hpp), box-filtered as the CPU resolve weighs
// its masks.
enum class CameraSamples { pixel_centre, mask_4x8 };

// Base-colour textures on the GPU: the scene's images (scene/texture.hpp, linear RGB) are
// uploaded once per GlScene as RGB32F 2D arrays with GL's mipmaps, one array per distinct
// image size, at most this many sizes (common_scene.glsl; more is a RuntimeFailure naming
// the limit). The uvs go in a vertex buffer of their own, made only when the scene has them.
constexpr int MAX_TEXTURE_ARRAYS = 4;

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

// The scene uploaded to the current GL context. Needs a current GL 4.5 context for its
// whole life (gl_context.hpp).
class GlScene {
 public:
  explicit GlScene(const SceneData& scene, const GlSceneOptions& options = {});
  ~GlScene();
  GlScene(const GlScene&) = delete;
  GlScene& operator=(const GlScene&) = delete;

  // Distance prepass over the six faces around `center`: per texel the Euclidean distance
  // to the nearest surface (NO_DISTANCE where none) and its object id (NO_OBJECT), faces
  // as cube_map.hpp defines them. `ids` may be null. Faces of n_s x n_t texels; n_t = 0
  // means square (a 8x, 4x supersampled face checks the 4x8 sample positions).
  void cube_distance(const glm::dvec3& center, int n, CubeImage* distance, CubeIds* ids, int n_t = 0);

  // Z-buffer Phong colour of the six faces seen from `center` (no shadows).
  CubeImage cube_color(const glm::dvec3& center, int n);

  // Z-buffer Phong image of the camera view, sampled at `samples`. Uses the shadow maps
  // and the environment map when they have been built. mask_4x8 renders the view at 8x
  // the columns and 4x the rows, in tiles, and averages each pixel's 32 samples.
  Image camera_color(const Camera& camera, CameraSamples samples = CameraSamples::pixel_centre);

  // The object id the Z-buffer sees at each of the camera's 4x8 samples per pixel
  // (samples.hpp): (8 width) x (4 height) values, row 0 at the top, NO_OBJECT where none.
  // Pixel (x, y), sample k is at row 4 y + k / 8, column 8 x + k % 8.
  std::vector<uint32_t> camera_objects(const Camera& camera);

  // One cube shadow map per light with cast_shadows, at n x n per face; later colour passes
  // are shadowed by them (the CPU's rule "shadows", shading.hpp): the distance to the
  // nearest opaque caster, and the translucent casters in front of it peeled into up to
  // MAX_SHADOW_PEELS layers, whose transmittances multiply. Returns how many lights. Maps
  // of the same size built before are kept (the lights do not change).
  int build_shadow_maps(int n);
  // Translucent layers the last build_shadow_maps peeled (0: no translucent caster), and
  // whether crossings were left beyond MAX_SHADOW_PEELS.
  int shadow_peels() const { return static_cast<int>(shadow_peels_.size()); }
  bool shadow_peels_capped() const { return shadow_peels_capped_; }
  // Layers the last camera_color drew (1 without coverage transparency), and whether
  // samples were left beyond MAX_CAMERA_LAYERS.
  int camera_layers() const { return camera_layers_; }
  bool camera_layers_capped() const { return camera_layers_capped_; }

  // The Z-buffer colour of the six faces around `center` (with shadows if built) kept on
  // the GPU as a cube texture; later camera passes look it up for kr and kt (Blinn & Newell
  // 1976, the `gpu` method's reflections).
  void build_environment(const glm::dvec3& center, int n);
  // Later camera passes look up no environment (max_depth 0, or nothing reflects).
  void drop_environment();
  // How later camera passes look the environment up: the envmap method's lookup direction
  // (R, bisector, position) and Schlick's weights for kr and kt (shading.hpp).
  void set_environment_lookup(EnvmapLookup lookup, bool fresnel) {
    lookup_ = lookup;
    fresnel_ = fresnel;
  }

  // abcube crosscheck: at the visible surface of each camera sample (the 4x8 grid, row 0 at
  // the top, as camera_objects), for the first 16 shadow-casting lights (`lights`, probe bit
  // k = lights[k]): the lights blocked by an opaque blocker according to the shadow volumes,
  // according to the cube shadow maps (build_shadow_maps first), and the lights the surface
  // faces.
  struct ShadowProbe {
    std::vector<int> lights;
    std::vector<uint16_t> volume, map, lit;
  };
  ShadowProbe camera_shadow_probe(const Camera& camera);

  // The exact camera pass (ExactCameraOptions): later camera_color calls use it where it
  // applies; exact_camera_stats() says what the last one did.
  void set_exact_camera(const ExactCameraOptions& options) { exact_ = options; }
  const ExactCameraStats& exact_camera_stats() const { return exact_stats_; }
  // Whether the next mask_4x8 camera pass would be the exact one (the options set, the
  // scene, this GL); exact_camera_stats() then says why not.
  bool exact_camera_possible() { return plan_exact_camera(); }
  const PlanarReflectors& planar_reflectors() const { return reflectors_; }
  const std::vector<uint8_t>& exact_pixels() const { return exact_pixels_; }

  // Textures sampled at level 0 with zero derivatives (bilinear), as the CPU's point
  // samples, instead of trilinear over the pass's footprint: `abcube crosscheck` compares
  // the lookups, not the two filters.
  void set_texture_level0(bool on) { texture_level0_ = on; }

  const GpuTimings& timings() const { return timings_; }
  // Whether the vertex buffers are the soup's own memory (GL_AMD_pinned_memory), not a copy.
  bool soup_pinned() const { return pinned_; }
  // Whether the vertex stage reads each triangle's ids from the soup's arrays (triangle_ids.glsl).
  bool triangle_ids() const { return triangle_ids_; }
  double near_distance() const { return near_; }
  int max_size() const { return max_size_; }

 private:
  struct Target;
  struct ExactBuffers;
  struct MirrorView;
  void draw(const GlProgram& program, const glm::mat4& clip, const glm::dvec3& center);
  // The view's uniforms (clip, model, eye, clip plane, mirror left out) set on `program`.
  void set_view(const GlProgram& program, const glm::mat4& clip, const MirrorView& view);
  void draw_scene(const GlProgram& program, const glm::mat4& clip, const MirrorView& view);
  void draw_reflector(const GlProgram& program, const glm::mat4& clip, const MirrorView& view, size_t r);
  Image camera_color_exact(const Camera& camera);
  bool plan_exact_camera();  // what the next camera pass can do exactly (exact_stats_)
  void render_view(const glm::mat4& clip, const MirrorView& view, int* views_left);
  void count_volumes(const glm::mat4& clip, const MirrorView& view);
  void fill_region(int level, const glm::vec4& colour);
  void build_volumes();
  std::string exact_mirrors_why_not() const;
  void make_exact_programs();
  void bind_lookups(const GlProgram& program, bool with_environment);
  void bind_lookup_target(int n);
  void clear_lookup_target(int n, bool distance);
  void upload_lights(const glm::dvec3& center);
  Target& target(int width, int height, bool distance_pass);

  const SceneData& scene_;
  // The scene's arrays: positions, normals, texture coordinates, each triangle's object and
  // material are the soup's (soup_buffer); vertex_ids_ each vertex's ids, where the vertex
  // stage reads no storage buffer of triangle ids (triangle_ids_ false).
  GLuint vao_ = 0, positions_ = 0, normals_ = 0, object_ids_ = 0, material_ids_ = 0, vertex_ids_ = 0;
  GLuint uv_vbo_ = 0, materials_ = 0, lights_ = 0;
  bool triangle_ids_ = false;
  // scene.vert and what goes before it: `before`, then triangle_ids.glsl where it is used.
  std::vector<const char*> scene_vertex_stage(const char* before = nullptr) const;
  bool pin_soup_ = true;
  bool pinned_ = false;  // every soup buffer is the soup's memory
  // A GL buffer holding `bytes` at `data`: that memory itself when pin_soup_ and the GL
  // can (the soup must then outlive the buffer), else a copy.
  GLuint soup_buffer(const void* data, size_t bytes);
  std::vector<GLuint> texture_arrays_;   // by size class; the material's code names array and layer
  std::vector<float> upload_textures();  // per material: -1, or array + MAX_TEXTURE_ARRAYS * layer
  GLuint shadow_maps_ = 0, environment_ = 0, lookup_fbo_ = 0, lookup_depth_ = 0;
  std::vector<GLuint> shadow_peels_;  // one cube-map array (a layer per light and face) per peel
  bool shadow_peels_capped_ = false;
  int camera_layers_ = 0;
  bool camera_layers_capped_ = false;
  int shadow_n_ = 0;
  std::vector<int> shadow_layer_;  // per light, -1 when it casts no shadows
  GLsizei vertex_count_ = 0;
  double near_ = 1e-4;
  int max_size_ = 0;
  void draw_shadow_casters(GLuint maps);
  void peel_translucent_casters(int n, int layers);
  // The lookup target's size (bind_lookup_target).
  int n_of_lookup_ = 0;
  // How camera passes look the environment up (set_environment_lookup).
  EnvmapLookup lookup_ = EnvmapLookup::reflected;
  bool fresnel_ = false;  // Schlick's weights for kr and kt (shading.hpp)
  bool texture_level0_ = false;
  std::unique_ptr<GlProgram> distance_program_, phong_program_, shadow_program_;
  std::unique_ptr<Target> target_;
  GpuTimings timings_;
  // The exact camera pass: the planar reflectors, each one's triangles as an index range of
  // portal_ebo_, the per-vertex reflector ids (portal_vbo_); the shadow volumes, one per
  // volume light (its index in volume_lights_ is its bit); its programs and buffers.
  ExactCameraOptions exact_;
  ExactCameraStats exact_stats_;
  std::vector<uint8_t> exact_pixels_;
  bool shadows_approximate_ = false;  // shadows from maps (no volumes), or lights past the volume counts
  PlanarReflectors reflectors_;
  GLuint portal_vbo_ = 0, portal_ebo_ = 0;
  std::vector<std::pair<size_t, size_t>> portal_ranges_;  // first index, count
  bool volumes_built_ = false;
  std::vector<int> volume_lights_;    // light index per count (its layer)
  std::vector<int> volume_bit_;       // per light: its opaque blockers' count, or -1
  std::vector<int> translucent_bit_;  // per light: its translucent blockers' count, or -1
  // Each volume light's volume (shadow_volume.hpp): its caps' codes, also in a storage
  // buffer each (volume_caps_, read by scene.vert's VOLUME_CAPS when the scene's own vertex
  // buffer draws the near caps), and its sides; its faces at infinity are clipped per view
  // and tile on the CPU into clipped_volume_ and drawn from clipped_vbo_.
  std::vector<ShadowVolume> volumes_;
  std::vector<GLuint> volume_caps_;
  struct CapRuns {  // runs of consecutive casting triangles, as vertex ranges of the scene's buffer
    std::vector<GLint> first;
    std::vector<GLsizei> count;
  };
  std::vector<CapRuns> cap_runs_;
  std::vector<ShadowVolumeVertex> clipped_volume_;
  GLuint clipped_vao_ = 0, clipped_vbo_ = 0;
  void draw_faces_at_infinity(int layer, const glm::mat4& clip, const MirrorView& view);
  std::string volume_caps_why_not() const;
  std::unique_ptr<GlProgram> exact_program_, fill_program_, volume_program_, probe_program_, resolve_program_;
  std::unique_ptr<GlProgram> ids_program_, groups_program_,
      depth_program_;  // per-group shading (camera_ids, camera_groups)
  struct VisibilityBuffers;
  std::unique_ptr<VisibilityBuffers> visibility_;
  void shade_groups(const glm::mat4& clip, const MirrorView& view, bool volumes);
  // Shading::pixels, unless its keys cannot hold every volume light's bit (camera_ids.frag:
  // 32) or the vertex buffer is larger than a shader storage block may be (the reason, "" when
  // it can).
  std::string shade_pixels_why_not() const;
  bool shade_pixels() const { return exact_stats_.shading_pixels; }
  GLuint resolve_fbo_ = 0, resolve_texture_ = 0;  // a tile's pixels (resolve_samples.frag)
  int resolve_w_ = 0, resolve_h_ = 0;
  GLuint recursed_ = 0;  // per view: which mirrors had their view drawn (camera_exact.frag)
  std::unique_ptr<ExactBuffers> exact_buffers_;
};

}  // namespace abcube
