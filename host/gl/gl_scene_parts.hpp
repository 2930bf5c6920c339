// What the techniques of one GlScene share (GlSceneParts): the uploaded scene, the
// framebuffers, the lookups every colour pass reads (shadow maps, environment map, textures),
// the shadow volumes whose counts the lights name, the two programs of the plain passes,
// and the timings. GlScene owns it; each technique reads it.
#pragma once
#include <memory>

#include "gl/gl_environment.hpp"
#include "gl/gl_targets.hpp"
#include "gl/gl_program.hpp"
#include "gl/gl_scene_buffers.hpp"
#include "gl/gl_shadow_maps.hpp"
#include "gl/gl_shadow_volumes.hpp"

namespace abcube {

struct GlSceneParts {
  GlSceneParts(const SceneData& scene, const GlSceneOptions& options);

  const SceneData& scene;
  GlSceneBuffers buffers;
  GlShadowMaps shadows;
  GlEnvironment environment;
  GlShadowVolumes volumes;
  LookupTarget lookup;
  GpuTimings timings;
  bool texture_level0 = false;  // GlScene::set_texture_level0
  // cube_distance.frag (distances and object ids) and phong.frag (the Z-buffer colour).
  std::unique_ptr<GlProgram> distance_program, phong_program;

  // The camera or cube-face target of this size and kind, kept while the next pass asks
  // for the same (a RuntimeFailure past GL_MAX_TEXTURE_SIZE).
  GlTarget& target(int width, int height, bool distance_pass);
  // The target the last target() call gave.
  GlTarget& current_target() { return *target_; }
  // The lights relative to `center`, with their shadow maps' layers and volume counts.
  void upload_lights(const glm::dvec3& center) const;
  // The shadow maps, the environment map (when `with_environment` and built) and the
  // textures bound for `program`, made current; leaves unit 0 active.
  void bind_lookups(const GlProgram& program, bool with_environment) const;

 private:
  std::unique_ptr<GlTarget> target_;
};

}  // namespace abcube
