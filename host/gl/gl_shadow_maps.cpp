// The cube shadow maps (GlShadowMaps) with their translucent peels, and the GL limit on
// their lights.
#include "gl/gl_shadow_maps.hpp"

#include <algorithm>
#include <string>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_targets.hpp"
#include "gl/gl_scene_buffers.hpp"
#include "material/shading.hpp"
#include "raster/cube_map.hpp"

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

GlShadowMaps::GlShadowMaps(const GlSceneBuffers& buffers)
    : buffers_(buffers),
      program_(std::make_unique<GlProgram>(buffers.vertex_stage(),
                                           std::vector<const char*>{"common_scene.glsl", "shadow_caster.frag"})) {}

GlShadowMaps::~GlShadowMaps() {
  glDeleteTextures(1, &maps_);
  glDeleteTextures(static_cast<GLsizei>(peels_.size()), peels_.data());
}

int GlShadowMaps::build(int n, LookupTarget& lookup, GpuTimings& timings) {
  const SceneData& scene = buffers_.scene();
  layer_.assign(scene.lights.size(), -1);
  int layers = 0;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    if (scene.lights[i].cast_shadows) layer_[i] = layers++;
  }
  if (layers == 0) return 0;
  // The lights are the scene's: maps built at this size by an earlier render are kept.
  if (maps_ != 0 && n_ == n) return layers;
  const Clock::time_point t0 = Clock::now();
  if (n > buffers_.max_size()) throw RuntimeFailure("shadow map " + std::to_string(n) + " exceeds GL_MAX_TEXTURE_SIZE");
  n_ = 0;  // the maps count as built (and are kept) only once they are whole
  glDeleteTextures(1, &maps_);
  glGenTextures(1, &maps_);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, maps_);
  glTexStorage3D(GL_TEXTURE_CUBE_MAP_ARRAY, 1, GL_R32F, n, n, 6 * layers);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  lookup.bind(n);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);  // no feedback: the opaque maps are the target
  glActiveTexture(GL_TEXTURE0);
  program_->use();
  glUniform1i(program_->uniform("u_peel"), -1);
  draw_casters(maps_, lookup);
  peel_translucent_casters(n, layers, lookup);
  glFinish();
  check_gl("cube shadow maps");
  n_ = n;
  timings.shadow_maps_ms += ms_since(t0);
  return layers;
}

// Draws the shadow program from every shadow-casting light into its six layers of `maps`
// (the lookup target, bound), each cleared first; the program's pass uniforms are set.
void GlShadowMaps::draw_casters(GLuint maps, const LookupTarget& lookup) const {
  const SceneData& scene = buffers_.scene();
  const GLenum attachments[] = {GL_COLOR_ATTACHMENT0};
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    if (layer_[i] < 0) continue;
    const glm::dvec3 light = scene.lights[i].position;
    program_->use();
    glUniform1f(program_->uniform("u_light_layer"), float(layer_[i]));
    for (int face = 0; face < CUBE_FACES; ++face) {
      check_deadline();  // a render's time limit, or a stop request, between passes
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, maps, 0, 6 * layer_[i] + face);
      glDrawBuffers(1, attachments);
      lookup.clear(true, scene.background);
      buffers_.draw(*program_, face_clip_matrix(face, glm::dvec3(0.0), buffers_.near_distance()), light, false);
    }
  }
}

// The translucent casters in front of the opaque ones, peeled one layer a pass (nearest
// first, shadow_caster.frag) until a pass draws nothing or MAX_SHADOW_PEELS are kept; one
// more pass then says whether crossings were left out (peels_capped()).
void GlShadowMaps::peel_translucent_casters(int n, int layers, const LookupTarget& lookup) {
  glDeleteTextures(static_cast<GLsizei>(peels_.size()), peels_.data());
  peels_.clear();
  peels_capped_ = false;
  bool translucent = false;
  for (const Material& m : buffers_.scene().materials) {
    const glm::dvec3 t = blocker_transmittance(m);
    translucent = translucent || (t != glm::dvec3(0.0) && t != glm::dvec3(1.0));
  }
  if (!translucent) return;
  GLuint query = 0;
  glGenQueries(1, &query);
  program_->use();
  glUniform1i(program_->uniform("u_opaque"), 1);
  glUniform1i(program_->uniform("u_previous"), static_cast<GLint>(PEEL_UNIT));
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
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, maps_);
    glActiveTexture(GL_TEXTURE0 + PEEL_UNIT);
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, k > 0 ? peels_.back() : 0);
    glActiveTexture(GL_TEXTURE0);
    program_->use();
    glUniform1i(program_->uniform("u_peel"), k);
    glBeginQuery(GL_ANY_SAMPLES_PASSED, query);
    draw_casters(peel, lookup);
    glEndQuery(GL_ANY_SAMPLES_PASSED);
    GLuint drew = 0;
    glGetQueryObjectuiv(query, GL_QUERY_RESULT, &drew);
    if (!drew || k == MAX_SHADOW_PEELS) {
      peels_capped_ = drew != 0;
      glDeleteTextures(1, &peel);
      break;
    }
    peels_.push_back(peel);
  }
  glDeleteQueries(1, &query);
  glActiveTexture(GL_TEXTURE0 + PEEL_UNIT);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);
  glActiveTexture(GL_TEXTURE0);
}

void GlShadowMaps::bind(const GlProgram& program) const {
  program.use();
  const bool shadows = maps_ != 0;
  glUniform1i(program.uniform("u_shadows"), shadows);
  glUniform1i(program.uniform("u_shadow_maps"), 1);
  glUniform1f(program.uniform("u_shadow_texel"), shadows ? float(2.0 / n_) : 0.f);
  glUniform1f(program.uniform("u_shadow_bias_texels"), float(SHADOW_BIAS_TEXELS));
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, maps_);
  glUniform1i(program.uniform("u_shadow_peels"), shadows ? static_cast<GLint>(peels_.size()) : 0);
  GLint units[MAX_SHADOW_PEELS];
  for (int k = 0; k < MAX_SHADOW_PEELS; ++k) {
    units[k] = static_cast<GLint>(PEEL_UNIT) + k;
    glActiveTexture(GL_TEXTURE0 + PEEL_UNIT + static_cast<GLenum>(k));
    glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY,
                  static_cast<size_t>(k) < peels_.size() ? peels_[static_cast<size_t>(k)] : 0);
  }
  glUniform1iv(program.uniform("u_shadow_peel_maps"), MAX_SHADOW_PEELS, units);
}

}  // namespace abcube
