// The exact camera pass's shadow volumes (course notes 3.3; Everitt & Kilgard 2002): built per
// volume light, counted depth-fail per view; and crosscheck's shadow probe, which reads them.
#include "gl/gl_passes.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_passes_internal.hpp"
#include "base/samples.hpp"
#include "gpu_geometry/shadow_volume.hpp"
#include "scene/tie_rule.hpp"
#include "material/shading.hpp"

namespace abcube {

// The near caps' codes are read from a storage buffer by the vertex stage (volume_caps.glsl).
std::string GlScene::volume_caps_why_not() const {
  GLint blocks = 0;
  GLint64 block = 0;
  glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &blocks);
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  if (blocks < 1) return "this GL offers no storage buffer to a vertex shader (the volumes' caps need one)";
  const uint64_t bytes = scene_.triangles->triangle_count();
  if (bytes > static_cast<uint64_t>(block)) {
    return "the volumes' caps' " + std::to_string(bytes) + " bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE " +
           std::to_string(block);
  }
  return "";
}

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

void GlScene::build_volumes() {
  if (volumes_built_) return;
  volumes_built_ = true;
  const Clock::time_point t0 = Clock::now();
  volume_bit_.assign(scene_.lights.size(), -1);
  translucent_bit_.assign(scene_.lights.size(), -1);
  bool translucent = false;
  for (const uint32_t id : scene_.triangles->material_id) {
    const glm::dvec3 t = blocker_transmittance(scene_.materials[id]);
    translucent = translucent || (t != glm::dvec3(0.0) && t != glm::dvec3(1.0));
  }
  const size_t per_light = translucent ? 2 : 1;
  for (size_t i = 0; i < scene_.lights.size() && volume_lights_.size() + per_light <= size_t{MAX_VOLUME_LIGHTS}; ++i) {
    if (!scene_.lights[i].cast_shadows) continue;
    for (const Blockers kind : {Blockers::opaque, Blockers::translucent}) {
      if (kind == Blockers::translucent && !translucent) continue;
      (kind == Blockers::opaque ? volume_bit_ : translucent_bit_)[i] = static_cast<int>(volume_lights_.size());
      volume_lights_.push_back(static_cast<int>(i));
      volumes_.push_back(build_shadow_volume(scene_, scene_.lights[i].position, kind));
      const ShadowVolume& v = volumes_.back();
      const size_t volume_triangles = v.triangle_count();
      // The caps' codes, four to a word of the storage buffer (byte k of word i is triangle
      // 4 i + k: a little-endian host, as every GL host this runs on).
      GLuint caps = 0;
      glGenBuffers(1, &caps);
      glBindBuffer(GL_SHADER_STORAGE_BUFFER, caps);
      const size_t bytes = (v.caps.size() + 3) / 4 * 4;
      glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<size_t>(bytes, 4)), nullptr,
                   GL_STATIC_DRAW);
      glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(v.caps.size()), v.caps.data());
      volume_caps_.push_back(caps);
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
      exact_stats_.volume_triangles += volume_triangles;
    }
  }
  glGenVertexArrays(1, &clipped_vao_);
  glBindVertexArray(clipped_vao_);
  glGenBuffers(1, &clipped_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, clipped_vbo_);
  volume_attributes();
  glBindVertexArray(vao_);
  exact_stats_.volume_lights = static_cast<int>(volume_lights_.size());
  exact_stats_.volume_build_ms = ms_since(t0);
  check_gl("shadow volumes upload");
}

// The view's shadow-volume counts: per volume light, in its layer, the
// depth-fail count of its volume's faces behind or at the view's surfaces (the view's depth
// is drawn), over the view's scissor (the colour pass reads them in its stencil region only).
void GlScene::count_volumes(const glm::mat4& clip, const MirrorView& view) {
  ExactBuffers& b = *exact_buffers_;
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
    set_view(*volume_program_, clip, view);
    glUniform1ui(volume_program_->uniform("u_skip_portal"), 0u);
    glUniform1i(volume_program_->uniform("u_caps"), 1);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOLUME_CAPS_BINDING, volume_caps_[static_cast<size_t>(layer)]);
    glBindVertexArray(vao_);
    const CapRuns& runs = cap_runs_[static_cast<size_t>(layer)];
    glMultiDrawArrays(GL_TRIANGLES, runs.first.data(), runs.count.data(), static_cast<GLsizei>(runs.first.size()));
    glUniform1i(volume_program_->uniform("u_caps"), 0);
    draw_faces_at_infinity(layer, clip, view);
    glDisable(GL_BLEND);
  }
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
  glBindVertexArray(vao_);
}

// A volume's faces at infinity, clipped on the CPU (shadow_volume.hpp) to this view and tile
// and drawn as window-space points: the identity for scene.vert's transform, no tie scale
// (applied), no mirror plane (clipped at).
void GlScene::draw_faces_at_infinity(int layer, const glm::mat4& clip, const MirrorView& view) {
  // The view's transform as set_view gives the GL (in double) and its mirror's plane
  // relative to its eye.
  glm::dmat4 linear = view.model;
  linear[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);
  const glm::dvec4 plane(glm::dvec3(view.plane), view.plane.w + glm::dot(glm::dvec3(view.plane), view.eye));
  const double tie_step = double(float(gl_tie_step(scene_.objects.size())));  // as set_view gives it
  const glm::mat4 identity(1.f);
  glUniformMatrix4fv(volume_program_->uniform("u_clip"), 1, GL_FALSE, &identity[0][0]);
  glUniform3d(volume_program_->uniform("u_center"), 0.0, 0.0, 0.0);
  glUniform1f(volume_program_->uniform("u_tie_step"), 0.f);
  glUniform4f(volume_program_->uniform("u_clip_plane"), 0.f, 0.f, 0.f, 1.f);
  glUniform1i(volume_program_->uniform("u_vertex_ids"), 1);  // -1 without triangle_ids.glsl: ignored
  glBindVertexArray(clipped_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, clipped_vbo_);
  // A run of faces at a time: their clipped triangles, then the GL's copy, stay small.
  constexpr size_t RUN = 65536;
  const ShadowVolume& volume = volumes_[static_cast<size_t>(layer)];
  for (size_t first = 0; first < faces_at_infinity(volume); first += RUN) {
    clipped_volume_.clear();
    clip_faces_at_infinity(volume, *scene_.triangles, glm::dmat4(clip) * linear, view.eye, tie_step,
                           view.level > 0 ? &plane : nullptr, &clipped_volume_, first, RUN);
    if (clipped_volume_.empty()) continue;
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(clipped_volume_.size() * sizeof(ShadowVolumeVertex)),
                 clipped_volume_.data(), GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(clipped_volume_.size()));
  }
  glUniform1i(volume_program_->uniform("u_vertex_ids"), 0);
}

GlScene::ShadowProbe GlScene::camera_shadow_probe(const Camera& camera) {
  constexpr int PROBED = 16;
  ShadowProbe out;
  std::vector<GLint> probe(64, -1);
  for (size_t i = 0; i < scene_.lights.size() && out.lights.size() < size_t{PROBED}; ++i) {
    if (!scene_.lights[i].cast_shadows) continue;
    if (i < probe.size()) probe[i] = static_cast<GLint>(out.lights.size());
    out.lights.push_back(static_cast<int>(i));
  }
  const int64_t full_w = int64_t{camera.width} * MASK_COLUMNS, full_h = int64_t{camera.height} * MASK_ROWS;
  const SampleTiles tiles(full_w, full_h, max_size_);
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  Target& t = target(tiles.target_w(), tiles.target_h(), false);
  make_exact_programs();
  build_volumes();
  if (!exact_buffers_ || exact_buffers_->width != t.width || exact_buffers_->height != t.height ||
      exact_buffers_->layers != static_cast<int>(volume_lights_.size())) {
    exact_buffers_.reset();
    exact_buffers_ = std::make_unique<ExactBuffers>(t, static_cast<int>(volume_lights_.size()));
  }
  const glm::mat4 clip = relative_camera_clip(camera, near_);
  const size_t grid = static_cast<size_t>(full_w * full_h);
  out.volume.assign(grid, 0);
  out.map.assign(grid, 0);
  out.lit.assign(grid, 0);
  std::vector<float> rgba(static_cast<size_t>(t.width) * static_cast<size_t>(t.height) * 4);
  const GLenum colour[] = {GL_COLOR_ATTACHMENT0};
  MirrorView view;
  view.eye = camera.position;
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      const glm::mat4 tile_clip = tiles.matrix(x0, y0) * clip;
      t.clear(scene_.background);
      const float none[4] = {0, 0, 0, 0};
      glClearBufferfv(GL_COLOR, 0, none);
      stencil_level(0);
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      draw_scene(*depth_program_, tile_clip, view);
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      if (!volume_lights_.empty()) count_volumes(tile_clip, view);
      glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
      glDrawBuffers(1, colour);
      stencil_level(0);
      glDepthFunc(GL_GEQUAL);
      bind_lookups(*probe_program_, false);
      upload_lights(view.eye);
      probe_program_->use();
      glUniform1iv(probe_program_->uniform("u_probe"), 64, probe.data());
      glActiveTexture(GL_TEXTURE0 + VOLUME_COUNT_UNIT);
      glBindTexture(GL_TEXTURE_2D_ARRAY, exact_buffers_->counts);
      glActiveTexture(GL_TEXTURE0);
      draw_scene(*probe_program_, tile_clip, view);
      glDepthFunc(GL_GREATER);
      glFinish();
      t.read(0, GL_RGBA, GL_FLOAT, rgba.data());
      for (int64_t gy = 0; gy < tile_h && y0 + gy < full_h; ++gy) {
        for (int64_t gx = 0; gx < tile_w && x0 + gx < full_w; ++gx) {
          const size_t k = tiles.index(gx, gy);
          const size_t g = static_cast<size_t>((full_h - 1 - (y0 + gy)) * full_w + x0 + gx);
          out.volume[g] = static_cast<uint16_t>(rgba[4 * k]);
          out.map[g] = static_cast<uint16_t>(rgba[4 * k + 1]);
          out.lit[g] = static_cast<uint16_t>(rgba[4 * k + 2]);
        }
      }
    }
  }
  glDisable(GL_STENCIL_TEST);
  glActiveTexture(GL_TEXTURE0 + VOLUME_COUNT_UNIT);
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  glActiveTexture(GL_TEXTURE0);
  check_gl("shadow probe");
  return out;
}

}  // namespace abcube
