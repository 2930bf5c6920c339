// The environment map (GlEnvironment): the Z-buffer colour of the six faces around a
// centre, kept on the GPU for the camera passes' kr and kt.
#include "gl/gl_environment.hpp"

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "gl/gl_targets.hpp"
#include "raster/cube_map.hpp"

namespace abcube {

void GlEnvironment::drop() {
  glDeleteTextures(1, &texture_);
  texture_ = 0;
}

void GlEnvironment::build(int n, LookupTarget& lookup, const glm::dvec3& background,
                          const std::function<void(int)>& draw_face) {
  drop();
  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_CUBE_MAP, texture_);
  glTexStorage2D(GL_TEXTURE_CUBE_MAP, 1, GL_RGBA32F, n, n);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  lookup.bind(n);
  const GLenum attachments[] = {GL_COLOR_ATTACHMENT0};
  for (int face = 0; face < CUBE_FACES; ++face) {
    check_deadline();
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                           GL_TEXTURE_CUBE_MAP_POSITIVE_X + static_cast<GLenum>(face), texture_, 0);
    glDrawBuffers(1, attachments);
    lookup.clear(false, background);
    draw_face(face);
  }
  glFinish();
  check_gl("environment map");
}

void GlEnvironment::set_uniforms(const GlProgram& program, bool use) const {
  glUniform1i(program.uniform("u_environment"), use && built());
  glUniform1i(program.uniform("u_lookup"), lookup_ == EnvmapLookup::bisector   ? 1
                                           : lookup_ == EnvmapLookup::position ? 2
                                                                               : 0);
  glUniform1i(program.uniform("u_fresnel"), fresnel_);
  glUniform1i(program.uniform("u_environment_map"), 2);
}

void GlEnvironment::bind_texture(bool use) const {
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_CUBE_MAP, use && built() ? texture_ : 0);
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace abcube
