// The exact camera pass's shadow volumes (GlShadowVolumes): built per volume light, counted
// depth-fail per view.
#include "gl/gl_shadow_volumes.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "base/timer.hpp"
#include "gl/gl_targets.hpp"
#include "gl/gl_scene_buffers.hpp"
#include "material/shading.hpp"
#include "scene/gpu_limits.hpp"
#include "scene/tie_rule.hpp"

namespace abcube {

// The counts beside the camera target (same size, same depth-stencil texture): a layer of
// an R32F array per volume light (additive), drawn through one framebuffer whose colour is
// the layer being counted. (A layer a light rather than four lights a layer of RGBA32F: a
// scene blends only the bytes of its lights.)
struct GlShadowVolumes::Counts {
  int width = 0, height = 0, layers = 0;
  GLuint counts = 0, fbo = 0;

  Counts(const GlTarget& t, int lights) : width(t.width), height(t.height), layers(lights) {
    glGenTextures(1, &counts);
    glBindTexture(GL_TEXTURE_2D_ARRAY, counts);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_R32F, width, height, std::max(layers, 1));
    // One level, read by texelFetch: complete only with a filter that needs no mipmaps.
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, counts, 0, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, t.depth, 0);
    check_framebuffer("shadow-volume");
  }
  ~Counts() {
    glDeleteTextures(1, &counts);
    glDeleteFramebuffers(1, &fbo);
  }
};

GlShadowVolumes::GlShadowVolumes(const GlSceneBuffers& buffers) : buffers_(buffers) {}

GlShadowVolumes::~GlShadowVolumes() {
  counts_.reset();
  glDeleteBuffers(static_cast<GLsizei>(caps_.size()), caps_.data());
  glDeleteBuffers(1, &clipped_vbo_);
  glDeleteVertexArrays(1, &clipped_vao_);
}

std::string GlShadowVolumes::why_not() const {
  GLint blocks = 0;
  GLint64 block = 0;
  glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &blocks);
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  if (blocks < 1) return "this GL offers no storage buffer to a vertex shader (the volumes' caps need one)";
  const uint64_t bytes = buffers_.scene().triangles->triangle_count();
  if (bytes > static_cast<uint64_t>(block)) {
    return "the volumes' caps' " + std::to_string(bytes) + " bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE " +
           std::to_string(block);
  }
  return "";
}

GLuint GlShadowVolumes::counts() const { return counts_ ? counts_->counts : 0; }

namespace {
// The bound vertex buffer holds ShadowVolumeVertex: scene.vert's position, object, reversed.
void volume_attributes() {
  const auto offset = [](size_t bytes) { return reinterpret_cast<const void*>(bytes); };
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(ShadowVolumeVertex),
                        offset(offsetof(ShadowVolumeVertex, position)));
  glVertexAttribIPointer(2, 1, GL_UNSIGNED_INT, sizeof(ShadowVolumeVertex),
                         offset(offsetof(ShadowVolumeVertex, object)));
  glVertexAttribIPointer(6, 1, GL_UNSIGNED_INT, sizeof(ShadowVolumeVertex),
                         offset(offsetof(ShadowVolumeVertex, reversed)));
  for (const GLuint a : {0u, 2u, 6u}) glEnableVertexAttribArray(a);
}
}  // namespace

void GlShadowVolumes::build() {
  if (built_) return;
  built_ = true;
  program_ = std::make_unique<GlProgram>(buffers_.vertex_stage("volume_caps.glsl"),
                                         std::vector<const char*>{"shadow_volume.frag"});
  const Clock::time_point t0 = Clock::now();
  const SceneData& scene = buffers_.scene();
  opaque_bit_.assign(scene.lights.size(), -1);
  translucent_bit_.assign(scene.lights.size(), -1);
  bool translucent = false;
  for (const uint32_t id : scene.triangles->material_id) {
    const glm::dvec3 t = blocker_transmittance(scene.materials[id]);
    translucent = translucent || (t != glm::dvec3(0.0) && t != glm::dvec3(1.0));
  }
  const size_t per_light = translucent ? 2 : 1;
  for (size_t i = 0; i < scene.lights.size() && lights_.size() + per_light <= size_t{MAX_VOLUME_LIGHTS}; ++i) {
    if (!scene.lights[i].cast_shadows) continue;
    add_volume(i, Blockers::opaque);
    if (translucent) add_volume(i, Blockers::translucent);
  }
  glGenVertexArrays(1, &clipped_vao_);
  glBindVertexArray(clipped_vao_);
  glGenBuffers(1, &clipped_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, clipped_vbo_);
  volume_attributes();
  buffers_.bind_vertex_array();
  build_ms_ = ms_since(t0);
  check_gl("shadow volumes upload");
}

void GlShadowVolumes::add_volume(size_t light, Blockers kind) {
  const SceneData& scene = buffers_.scene();
  (kind == Blockers::opaque ? opaque_bit_ : translucent_bit_)[light] = static_cast<int>(lights_.size());
  lights_.push_back(static_cast<int>(light));
  volumes_.push_back(build_shadow_volume(scene, scene.lights[light].position, kind));
  const ShadowVolume& v = volumes_.back();
  // The caps' codes, four to a word of the storage buffer (byte k of word i is triangle
  // 4 i + k: a little-endian host, as every GL host this runs on).
  GLuint caps = 0;
  glGenBuffers(1, &caps);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, caps);
  const size_t bytes = (v.caps.size() + 3) / 4 * 4;
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<size_t>(bytes, 4)), nullptr, GL_STATIC_DRAW);
  glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(v.caps.size()), v.caps.data());
  caps_.push_back(caps);
  // The runs of consecutive casting triangles, drawn alone (a light's translucent volume
  // has a few glass blockers among every triangle of the scene).
  CapRuns runs;
  for (size_t t = 0; t < v.caps.size();) {
    if (v.caps[t] == NO_CAP) {
      ++t;
      continue;
    }
    size_t end = t;
    while (end < v.caps.size() && v.caps[end] != NO_CAP) ++end;
    runs.first.push_back(static_cast<GLint>(3 * t));
    runs.count.push_back(static_cast<GLsizei>(3 * (end - t)));
    t = end;
  }
  cap_runs_.push_back(std::move(runs));
  triangles_ += v.triangle_count();
}

void GlShadowVolumes::attach(const GlTarget& t) {
  if (!counts_ || counts_->width != t.width || counts_->height != t.height ||
      counts_->layers != static_cast<int>(lights_.size())) {
    counts_.reset();
    counts_ = std::make_unique<Counts>(t, static_cast<int>(lights_.size()));
  }
}

void GlShadowVolumes::count(const glm::mat4& clip, const MirrorView& view) {
  Counts& b = *counts_;
  const GLenum one[] = {GL_COLOR_ATTACHMENT0};
  glBindFramebuffer(GL_FRAMEBUFFER, b.fbo);
  glDrawBuffers(1, one);
  stencil_level(view.level);
  glDepthFunc(GL_LEQUAL);  // reversed Z: at or behind the stored surface
  glDepthMask(GL_FALSE);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ONE);
  for (int layer = 0; layer < b.layers; ++layer) {
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, b.counts, 0, layer);
    const float zero[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);  // within the scissor
    glEnable(GL_BLEND);
    // Clipped at the view's mirror as its surfaces are (a near cap and its surface cut alike
    // keep the same depths); what is cut lies behind the mirror, where no counted ray goes.
    // The near caps: the scene's own vertex buffer, its runs of casting triangles, each
    // triangle with its cap's code (every portal's cap is drawn).
    buffers_.set_view(*program_, clip, view);
    glUniform1ui(program_->uniform("u_skip_portal"), 0u);
    glUniform1i(program_->uniform("u_caps"), 1);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOLUME_CAPS_BINDING, caps_[static_cast<size_t>(layer)]);
    buffers_.bind_vertex_array();
    const CapRuns& runs = cap_runs_[static_cast<size_t>(layer)];
    glMultiDrawArrays(GL_TRIANGLES, runs.first.data(), runs.count.data(), static_cast<GLsizei>(runs.first.size()));
    glUniform1i(program_->uniform("u_caps"), 0);
    draw_faces_at_infinity(layer, clip, view);
    glDisable(GL_BLEND);
  }
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
  buffers_.bind_vertex_array();
}

// A volume's faces at infinity, clipped on the CPU (shadow_volume.hpp) to this view and tile
// and drawn as window-space points: the identity for scene.vert's transform, no tie scale
// (applied), no mirror plane (clipped at).
void GlShadowVolumes::draw_faces_at_infinity(int layer, const glm::mat4& clip, const MirrorView& view) {
  // The view's transform as set_view gives the GL (in double) and its mirror's plane
  // relative to its eye.
  const glm::dvec4 plane(glm::dvec3(view.plane), view.plane.w + glm::dot(glm::dvec3(view.plane), view.eye));
  const double tie_step = double(float(gl_tie_step(buffers_.scene().objects.size())));  // as set_view gives it
  const glm::mat4 identity(1.f);
  glUniformMatrix4fv(program_->uniform("u_clip"), 1, GL_FALSE, &identity[0][0]);
  glUniform3d(program_->uniform("u_center"), 0.0, 0.0, 0.0);
  glUniform1f(program_->uniform("u_tie_step"), 0.f);
  glUniform4f(program_->uniform("u_clip_plane"), 0.f, 0.f, 0.f, 1.f);
  glUniform1i(program_->uniform("u_vertex_ids"), 1);  // -1 without triangle_ids.glsl: ignored
  glBindVertexArray(clipped_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, clipped_vbo_);
  // A run of faces at a time: their clipped triangles, then the GL's copy, stay small.
  constexpr size_t RUN = 65536;
  const ShadowVolume& volume = volumes_[static_cast<size_t>(layer)];
  for (size_t first = 0; first < faces_at_infinity(volume); first += RUN) {
    clipped_.clear();
    clip_faces_at_infinity(volume, *buffers_.scene().triangles, glm::dmat4(clip) * view.linear(), view.eye, tie_step,
                           view.level > 0 ? &plane : nullptr, &clipped_, first, RUN);
    if (clipped_.empty()) continue;
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(clipped_.size() * sizeof(ShadowVolumeVertex)),
                 clipped_.data(), GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(clipped_.size()));
  }
  glUniform1i(program_->uniform("u_vertex_ids"), 0);
}

}  // namespace abcube
