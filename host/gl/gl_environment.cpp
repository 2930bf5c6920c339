// The environment map (GlScene::build_environment): the Z-buffer colour of the six faces
// around a centre, kept on the GPU for the camera passes' kr and kt.
#include "gl/gl_passes.hpp"

#include <string>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "raster/cube_map.hpp"

namespace abcube {

void GlScene::drop_environment() {
  glDeleteTextures(1, &environment_);
  environment_ = 0;
}

void GlScene::build_environment(const glm::dvec3& center, int n) {
  const Clock::time_point t0 = Clock::now();
  if (n > max_size_) throw RuntimeFailure("environment map " + std::to_string(n) + " exceeds GL_MAX_TEXTURE_SIZE");
  drop_environment();
  glGenTextures(1, &environment_);
  glBindTexture(GL_TEXTURE_CUBE_MAP, environment_);
  glTexStorage2D(GL_TEXTURE_CUBE_MAP, 1, GL_RGBA32F, n, n);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  bind_lookup_target(n);
  upload_lights(center);
  bind_lookups(*phong_program_, false);  // no environment inside the environment
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0};
  for (int face = 0; face < CUBE_FACES; ++face) {
    check_deadline();
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                           GL_TEXTURE_CUBE_MAP_POSITIVE_X + static_cast<GLenum>(face), environment_, 0);
    glDrawBuffers(1, buffers);
    clear_lookup_target(n, false);
    draw(*phong_program_, face_clip_matrix(face, glm::dvec3(0.0), near_), center);
  }
  glFinish();
  check_gl("environment map");
  timings_.environment_ms += ms_since(t0);
}

}  // namespace abcube
