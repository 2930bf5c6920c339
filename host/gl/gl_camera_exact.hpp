// The camera pass of the gpu method where the GPU is exact (GlExactCamera; gl_types.hpp
// ExactCameraOptions; docs/design/gl-camera-exact.md). The stencil holds the mirror level of
// the view a sample shows: each visible planar mirror marks its samples, clears them, and
// draws the scene reflected about its plane there (gl_planar_mirrors.hpp), recursively to
// max_depth, so the virtual view is what the reflected rays of those very samples meet; the
// colour pass blends it in, C = C_local + kr * C_behind. Shadows of opaque blockers come
// from the volumes' counts (gl_shadow_volumes.hpp); the colour is shaded once a sample
// (camera_exact.frag) or once a pixel and surface (gl_shading_groups.hpp). Each pixel's 32
// samples are box-filtered on the GPU, and a pixel is flagged where a sample met a surface
// the GPU only approximates (the hybrid method redoes those on the CPU).
#pragma once
#include <glad/gl.h>

#include <memory>
#include <string>
#include <vector>

#include "gl/gl_types.hpp"
#include "io/image.hpp"
#include "gl/gl_planar_mirrors.hpp"
#include "gl/gl_program.hpp"

namespace abcube {

struct GlSceneParts;
struct GlTarget;
struct MirrorView;
class GlShadingGroups;
struct ViewShading;

class GlExactCamera {
 public:
  // Adds the planar mirrors to the scene's buffers; the programs are made on first use.
  explicit GlExactCamera(GlSceneParts& parts);
  ~GlExactCamera();
  GlExactCamera(const GlExactCamera&) = delete;
  GlExactCamera& operator=(const GlExactCamera&) = delete;

  void set_options(const ExactCameraOptions& options) { options_ = options; }
  // What the next render can do exactly (the options, the scene, this GL): false when
  // nothing; stats() then says why.
  bool plan();
  // The camera's view at its 4x8 samples, box-filtered (plan() first).
  Image render(const Camera& camera);

  const ExactCameraStats& stats() const { return stats_; }
  // Per pixel of the last render: 1 when none of its samples met an approximated surface.
  const std::vector<uint8_t>& pixels() const { return pixels_; }
  const PlanarReflectors& reflectors() const { return mirrors_.reflectors(); }

 private:
  void make_programs();
  void prepare(const GlTarget& target);
  void render_view(const glm::mat4& clip, const MirrorView& view, int* views_left);
  void draw_mirror_views(const glm::mat4& clip, const MirrorView& view, int* views_left,
                         std::vector<uint32_t>* recursed);
  void draw_behind_mirror(const glm::mat4& clip, const MirrorView& view, size_t r, double side,
                          const glm::ivec4& bounds, int* views_left);
  void shade_view(const glm::mat4& clip, const MirrorView& view, const std::vector<uint32_t>& recursed);
  void bind_view(const MirrorView& view) const;
  void fill_region(int level, const glm::vec4& colour);
  void resolve_tile(const GlTarget& target, int pw, int ph, std::vector<float>* rgba);
  ViewShading view_shading(const MirrorView& view) const;
  std::string mirrors_why_not() const;

  GlSceneParts& parts_;
  ExactCameraOptions options_;
  ExactCameraStats stats_;
  std::vector<uint8_t> pixels_;
  bool shadows_approximate_ = false;  // shadows from maps (no volumes), or lights past the volume counts
  GlPlanarMirrors mirrors_;
  std::unique_ptr<GlShadingGroups> groups_;
  std::unique_ptr<GlProgram> exact_program_, depth_program_, fill_program_, resolve_program_;
  GLuint recursed_ = 0;                           // per view: which mirrors had their view drawn (camera_surface.glsl)
  GLuint resolve_fbo_ = 0, resolve_texture_ = 0;  // a tile's pixels (resolve_samples.frag)
  int resolve_w_ = 0, resolve_h_ = 0;
};

}  // namespace abcube
