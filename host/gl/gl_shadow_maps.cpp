// The cube shadow maps (GlScene::build_shadow_maps) with their translucent peels, the GL limit
// on their lights, and the lookup target they and the environment map are rendered in.
#include "gl/gl_passes.hpp"

#include <algorithm>
#include <string>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_passes_internal.hpp"
#include "raster/cube_map.hpp"
#include "material/shading.hpp"

namespace abcube {

int gl_shadow_light_limit() {
  GLint layers = 0;
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &layers);
  return std::max(layers, 0) / CUBE_FACES;
}

void check_gl_limits(const SceneData& scene) {
  size_t casting = 0;
  for (const PointLight& l : scene.lights) casting += l.cast_shadows ? 1 : 0;
  const int limit = gl_shadow_light_limit();
  if (casting > static_cast<size_t>(limit)) {
    throw InputError(scene.file + ": lights: " + std::to_string(casting) +
                     " cast shadows; --method gpu holds the shadow maps "
                     "of at most " +
                     std::to_string(limit) + " here (GL_MAX_ARRAY_TEXTURE_LAYERS " +
                     std::to_string(limit * CUBE_FACES) +
                     " / 6 faces): set \"cast_shadows\": false on some, or use a CPU method");
  }
}

int GlScene::build_shadow_maps(int n) {
  shadow_layer_.assign(scene_.lights.size(), -1);
  int layers = 0;
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    if (scene_.lights[i].cast_shadows) shadow_layer_[i] = layers++;
  }
  if (layers == 0) return 0;
  // The lights are the scene's: maps built at this size by an earlier render are kept.
  if (shadow_maps_ != 0 && shadow_n_ == n) return layers;
  const Clock::time_point t0 = Clock::now();
  if (n > max_size_) throw RuntimeFailure("shadow map " + std::to_string(n) + " exceeds GL_MAX_TEXTURE_SIZE");
  shadow_n_ = 0;  // the maps count as built (and are kept) only once they are whole
  glDeleteTextures(1, &shadow_maps_);
  glGenTextures(1, &shadow_maps_);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, shadow_maps_);
  glTexStorage3D(GL_TEXTURE_CUBE_MAP_ARRAY, 1, GL_R32F, n, n, 6 * layers);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  bind_lookup_target(n);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);  // no feedback: the opaque maps are the target
  glActiveTexture(GL_TEXTURE0);
  shadow_program_->use();
  glUniform1i(shadow_program_->uniform("u_peel"), -1);
  draw_shadow_casters(shadow_maps_);
  peel_translucent_casters(n, layers);
  glFinish();
  check_gl("cube shadow maps");
  shadow_n_ = n;
  timings_.shadow_maps_ms += ms_since(t0);
  return layers;
}

// Draws the shadow program from every shadow-casting light into its six layers of `maps`
// (the lookup target, bound), each cleared first; the program's pass uniforms are set.
void GlScene::draw_shadow_casters(GLuint maps) {
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0};
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    if (shadow_layer_[i] < 0) continue;
    const glm::dvec3 light = scene_.lights[i].position;
    shadow_program_->use();
    glUniform1f(shadow_program_->uniform("u_light_layer"), float(shadow_layer_[i]));
    for (int face = 0; face < CUBE_FACES; ++face) {
      check_deadline();  // a render's time limit, or a stop request, between passes
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, maps, 0, 6 * shadow_layer_[i] + face);
      glDrawBuffers(1, buffers);
      clear_lookup_target(n_of_lookup_, true);
      draw(*shadow_program_, face_clip_matrix(face, glm::dvec3(0.0), near_), light);
    }
  }
}

// The translucent casters in front of the opaque ones, peeled one layer a pass (nearest
// first, shadow_caster.frag) until a pass draws nothing or MAX_SHADOW_PEELS are kept; one
// more pass then says whether crossings were left out (shadow_peels_capped()).
void GlScene::peel_translucent_casters(int n, int layers) {
  glDeleteTextures(static_cast<GLsizei>(shadow_peels_.size()), shadow_peels_.data());
  shadow_peels_.clear();
  shadow_peels_capped_ = false;
  bool translucent = false;
  for (const Material& m : scene_.materials) {
    const glm::dvec3 t = blocker_transmittance(m);
    translucent = translucent || (t != glm::dvec3(0.0) && t != glm::dvec3(1.0));
  }
  if (!translucent) return;
  GLuint query = 0;
  glGenQueries(1, &query);
  shadow_program_->use();
  glUniform1i(shadow_program_->uniform("u_opaque"), 1);
  glUniform1i(shadow_program_->uniform("u_previous"), static_cast<GLint>(PEEL_UNIT));
  for (int k = 0; k <= MAX_SHADOW_PEELS; ++k) {
    check_deadline();
    GLuint peel = 0;
    glGenTextures(1, &peel);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, peel);
    glTexStorage3D(GL_TEXTURE_CUBE_MAP_ARRAY, 1, GL_RGBA32F, n, n, 6 * layers);
    glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, shadow_maps_);
    glActiveTexture(GL_TEXTURE0 + PEEL_UNIT);
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, k > 0 ? shadow_peels_.back() : 0);
    glActiveTexture(GL_TEXTURE0);
    shadow_program_->use();
    glUniform1i(shadow_program_->uniform("u_peel"), k);
    glBeginQuery(GL_ANY_SAMPLES_PASSED, query);
    draw_shadow_casters(peel);
    glEndQuery(GL_ANY_SAMPLES_PASSED);
    GLuint drew = 0;
    glGetQueryObjectuiv(query, GL_QUERY_RESULT, &drew);
    if (!drew || k == MAX_SHADOW_PEELS) {
      shadow_peels_capped_ = drew != 0;
      glDeleteTextures(1, &peel);
      break;
    }
    shadow_peels_.push_back(peel);
  }
  glDeleteQueries(1, &query);
  glActiveTexture(GL_TEXTURE0 + PEEL_UNIT);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);
  glActiveTexture(GL_TEXTURE0);
}

// Binds the framebuffer that renders into the lookup textures, with an n x n depth buffer.
void GlScene::bind_lookup_target(int n) {
  n_of_lookup_ = n;
  if (!lookup_fbo_) glGenFramebuffers(1, &lookup_fbo_);
  glDeleteRenderbuffers(1, &lookup_depth_);
  glGenRenderbuffers(1, &lookup_depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, lookup_depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, n, n);
  glBindFramebuffer(GL_FRAMEBUFFER, lookup_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, lookup_depth_);
}

// Clears the lookup framebuffer (shadow map: +infinity; environment: background).
void GlScene::clear_lookup_target(int n, bool distance) {
  glViewport(0, 0, n, n);
  set_pass_state();
  const float zero_depth = 0.f;
  glClearBufferfv(GL_DEPTH, 0, &zero_depth);
  const glm::dvec3& b = scene_.background;
  const float far[4] = {NO_DISTANCE, 0, 0, 0};
  const float bg[4] = {float(b.x), float(b.y), float(b.z), 1.f};
  glClearBufferfv(GL_COLOR, 0, distance ? far : bg);
}

}  // namespace abcube
