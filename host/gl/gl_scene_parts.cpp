// The parts the techniques of one GlScene share (gl_scene_parts.hpp): the upload, the
// lookups bound for a colour pass, the lights, the target.
#include "gl/gl_scene_parts.hpp"

#include <memory>
#include <string>
#include <vector>

#include "base/error.hpp"

namespace abcube {

GlSceneParts::GlSceneParts(const SceneData& s, const GlSceneOptions& options)
    : scene(s), buffers(s, options), shadows(buffers), volumes(buffers) {
  distance_program =
      std::make_unique<GlProgram>(buffers.vertex_stage(), std::vector<const char*>{"cube_distance.frag"});
  phong_program = std::make_unique<GlProgram>(
      buffers.vertex_stage(), std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "phong.frag"});
  // Every sampler of the phong program on a unit of its own type (two sampler types on one
  // unit is an error at draw time, even when one is never read).
  phong_program->use();
  glUniform1i(phong_program->uniform("u_previous"), static_cast<GLint>(CAMERA_PREVIOUS_UNIT));
  glUniform1i(phong_program->uniform("u_volume_counts"), static_cast<GLint>(VOLUME_COUNT_UNIT));
}

GlTarget& GlSceneParts::target(int width, int height, bool distance_pass) {
  const int max_size = buffers.max_size();
  if (width < 1 || height < 1 || width > max_size || height > max_size) {
    throw RuntimeFailure("GL target " + std::to_string(width) + "x" + std::to_string(height) +
                         " exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(max_size));
  }
  if (!target_ || target_->width != width || target_->height != height || target_->distance_pass != distance_pass) {
    target_.reset();
    target_ = std::make_unique<GlTarget>(width, height, distance_pass);
  }
  return *target_;
}

void GlSceneParts::upload_lights(const glm::dvec3& center) const {
  buffers.upload_lights(center, shadows.layers(), volumes.opaque_bit(), volumes.translucent_bit());
}

void GlSceneParts::bind_lookups(const GlProgram& program, bool with_environment) const {
  shadows.bind(program);
  environment.set_uniforms(program, with_environment);
  buffers.bind_textures(program, texture_level0);
  environment.bind_texture(with_environment);
}

}  // namespace abcube
