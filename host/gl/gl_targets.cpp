// The framebuffers the GL passes render into: the camera and cube-face target, and the
// lookup target of the cube textures (gl_targets.hpp).
#include <string>

#include "gl/gl_targets.hpp"

namespace abcube {

void check_framebuffer(const std::string& what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw RuntimeFailure(what + " framebuffer incomplete (status " + std::to_string(status) + ")");
  }
}

GlTarget::GlTarget(int w, int h, bool distance) : width(w), height(h), distance_pass(distance) {
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  auto make = [&](GLenum format, GLenum attachment) {
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, format, w, h);
    glFramebufferTexture2D(GL_FRAMEBUFFER, attachment, GL_TEXTURE_2D, tex, 0);
    return tex;
  };
  color0 = make(distance ? GL_R32F : GL_RGBA32F, GL_COLOR_ATTACHMENT0);
  color1 = make(distance ? GL_R32UI : GL_RG32F, GL_COLOR_ATTACHMENT1);
  depth = make(GL_DEPTH32F_STENCIL8, GL_DEPTH_STENCIL_ATTACHMENT);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, buffers);
  check_framebuffer(std::to_string(w) + "x" + std::to_string(h));
}

GlTarget::~GlTarget() {
  const GLuint textures[] = {color0, color1, depth};
  glDeleteTextures(3, textures);
  glDeleteFramebuffers(1, &fbo);
}

void GlTarget::clear(const glm::dvec3& background) const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, width, height);
  set_pass_state();
  glClearBufferfi(GL_DEPTH_STENCIL, 0, 0.f, 0);  // reversed Z: 0 is infinitely far; stencil level 0
  if (distance_pass) {
    const float far[4] = {NO_DISTANCE, 0, 0, 0};
    const GLuint none[4] = {NO_OBJECT, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, far);
    glClearBufferuiv(GL_COLOR, 1, none);
  } else {
    const float bg[4] = {float(background.x), float(background.y), float(background.z), 1.f};
    const float none[4] = {NO_DISTANCE, -1.f, 0, 0};
    glClearBufferfv(GL_COLOR, 0, bg);
    glClearBufferfv(GL_COLOR, 1, none);
  }
}

void GlTarget::read(int index, GLenum format, GLenum type, void* out) const {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, format, type, out);
}

LookupTarget::~LookupTarget() {
  glDeleteRenderbuffers(1, &depth);
  glDeleteFramebuffers(1, &fbo);
}

void LookupTarget::bind(int size) {
  n = size;
  if (!fbo) glGenFramebuffers(1, &fbo);
  glDeleteRenderbuffers(1, &depth);
  glGenRenderbuffers(1, &depth);
  glBindRenderbuffer(GL_RENDERBUFFER, depth);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, n, n);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
}

void LookupTarget::clear(bool distance, const glm::dvec3& background) const {
  glViewport(0, 0, n, n);
  set_pass_state();
  const float zero_depth = 0.f;
  glClearBufferfv(GL_DEPTH, 0, &zero_depth);
  const float far[4] = {NO_DISTANCE, 0, 0, 0};
  const float bg[4] = {float(background.x), float(background.y), float(background.z), 1.f};
  glClearBufferfv(GL_COLOR, 0, distance ? far : bg);
}

}  // namespace abcube
