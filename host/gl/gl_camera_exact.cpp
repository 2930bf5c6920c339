// The camera pass of the gpu method where the GPU is exact (gl_passes.hpp
// ExactCameraOptions). PLANAR MIRRORS (course notes 4.1.2; Kilgard 1999): the stencil holds
// the mirror level of the view a sample shows; each visible reflector marks its samples,
// clears them, and draws the scene reflected about its plane there (clipped at the mirror,
// recursively to max_depth), so the virtual view is what the reflected rays of those very
// samples meet; the colour pass blends it in, C = C_local + kr * C_behind. SHADOW VOLUMES
// (course notes 3.3; Everitt & Kilgard 2002): per volume light, a depth-fail count of its
// faces at each sample, S_l = 0 where it is not 0. docs/design/gl-camera-exact.md has the
// whole argument.
#include <glad/gl.h>

#include <algorithm>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_passes.hpp"
#include "gl/gl_passes_internal.hpp"
#include "raster/cube_map.hpp"
#include "raster/samples.hpp"
#include "scene/shadow_volume.hpp"
#include "shading/shading.hpp"

namespace abcube {

namespace {

// The reflection about the plane dot(n, x) + d = 0 (n unit), as a 4x4 matrix.
glm::dmat4 reflection_matrix(const glm::dvec3& n, double d) {
  glm::dmat4 r(1.0);
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) r[c][k] -= 2.0 * n[k] * n[c];
    r[3][c] = -2.0 * d * n[c];
  }
  return r;
}

// The pixels of the tile (width x height) that triangles `r` of the soup cover when drawn
// through `clip_model` relative to `eye` (scene.vert), within `parent` (x, y, width, height); the parent itself when one
// of their corners is behind the eye. Empty (zero size) when they fall outside.
glm::ivec4 projected_bounds(const TriangleSoup& soup, const std::vector<uint32_t>& triangles, const glm::dmat4& clip_model,
                            const glm::dvec3& eye, const glm::ivec4& parent, int width, int height) {
  double lo_x = 1e300, lo_y = 1e300, hi_x = -1e300, hi_y = -1e300;
  for (const uint32_t t : triangles) {
    for (size_t k = 0; k < 3; ++k) {
      const glm::dvec4 c = clip_model * glm::dvec4(glm::dvec3(soup.positions[3 * static_cast<size_t>(t) + k]) - eye, 1.0);
      if (!(c.w > 0.0)) return parent;
      const double x = (c.x / c.w * 0.5 + 0.5) * width, y = (c.y / c.w * 0.5 + 0.5) * height;
      lo_x = std::min(lo_x, x), lo_y = std::min(lo_y, y), hi_x = std::max(hi_x, x), hi_y = std::max(hi_y, y);
    }
  }
  // One pixel of margin each way: the rasteriser's own rounding.
  const double x0 = std::max(std::floor(lo_x) - 1.0, double(parent.x)), y0 = std::max(std::floor(lo_y) - 1.0, double(parent.y));
  const double x1 = std::min(std::ceil(hi_x) + 1.0, double(parent.x + parent.z));
  const double y1 = std::min(std::ceil(hi_y) + 1.0, double(parent.y + parent.w));
  if (!(x1 > x0) || !(y1 > y0)) return glm::ivec4(0);
  return glm::ivec4(int(x0), int(y0), int(x1 - x0), int(y1 - y0));
}

// The stencil test of a view of level L: draw where the stencil is L, change nothing.
void stencil_level(int level) {
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_EQUAL, level, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glStencilMask(0xff);
}

}  // namespace

std::string GlScene::exact_mirrors_why_not() const {
  if (reflectors_.reflectors.empty()) return "no planar reflector";
  if (exact_.max_depth <= 0) return "max_depth 0: no reflected ray";
  return "";
}

bool GlScene::plan_exact_camera() {
  ExactCameraStats& s = exact_stats_;
  s.mirrors = s.volumes = s.plain = false;
  s.mirrors_why = s.volumes_why = "";
  s.mirror_views = s.mirror_views_empty = s.mirror_views_over_budget = 0;
  s.samples_approximate = s.pixels_exact = 0;
  s.deepest_level = 0;
  s.reflectors = reflectors_.reflectors.size();
  s.curved_reflective_triangles = reflectors_.curved_triangles;
  if (!exact_.planar_mirrors && !exact_.shadow_volumes && !exact_.always) return false;
  std::string both;
  for (const uint32_t id : scene_.triangles->material_id) {
    if (scene_.materials[id].opacity < 1.0) both = "coverage transparency (the peeled camera pass)";
  }
  GLint units = 0, dual = 0;
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
  glGetIntegerv(GL_MAX_DUAL_SOURCE_DRAW_BUFFERS, &dual);
  if (units <= static_cast<GLint>(VOLUME_COUNT_UNIT) || dual < 1) {
    both = "this GL offers " + std::to_string(units) + " texture units and " + std::to_string(dual) +
           " dual-source draw buffers (17 and 1 needed)";
  }
  bool casts = false;
  for (const PointLight& l : scene_.lights) casts = casts || l.cast_shadows;

  if (exact_.planar_mirrors) {
    s.mirrors_why = both.empty() ? exact_mirrors_why_not() : both;
    s.mirrors = s.mirrors_why.empty();
  }
  if (exact_.shadow_volumes) {
    s.volumes_why = !both.empty() ? both : casts ? volume_caps_why_not() : "no light casts shadows";
    s.volumes = s.volumes_why.empty();
  }
  // What the pass leaves approximate in every lit sample: shadows by maps (and lights past
  // the volumes' counts: camera_color_exact, once the volumes are built).
  shadows_approximate_ = casts && !s.volumes;
  s.plain = !s.mirrors && !s.volumes && exact_.always && both.empty();
  return s.mirrors || s.volumes || s.plain;
}

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

std::string GlScene::shade_pixels_why_not() const {
  if (volume_lights_.size() > 32) {
    return std::to_string(volume_lights_.size()) + " volume counts (a sample's key holds 32)";
  }
  GLint64 block = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  const uint64_t bytes = static_cast<uint64_t>(vertex_count_) * VERTEX_ARRAY_BYTES;
  if (bytes > static_cast<uint64_t>(block)) {
    return "the vertex positions' " + std::to_string(bytes) + " bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE " +
           std::to_string(block);
  }
  return "";
}

namespace {
// The bound vertex buffer holds ShadowVolumeVertex: scene.vert's position, object, reversed.
void volume_attributes() {
  const auto offset = [](size_t bytes) { return reinterpret_cast<const void*>(bytes); };
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(ShadowVolumeVertex), offset(offsetof(ShadowVolumeVertex, position)));
  glVertexAttribIPointer(2, 1, GL_UNSIGNED_INT, sizeof(ShadowVolumeVertex), offset(offsetof(ShadowVolumeVertex, object)));
  glVertexAttribIPointer(6, 1, GL_UNSIGNED_INT, sizeof(ShadowVolumeVertex), offset(offsetof(ShadowVolumeVertex, reversed)));
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
    glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<size_t>(bytes, 4)), nullptr, GL_STATIC_DRAW);
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

// Fills the region of stencil level `level` of the bound framebuffer's first attachment
// with `colour` and its depth with the far plane (fill.vert).
void GlScene::fill_region(int level, const glm::vec4& colour) {
  fill_program_->use();
  glUniform4f(fill_program_->uniform("u_fill"), colour.r, colour.g, colour.b, colour.a);
  stencil_level(level);
  glDepthFunc(GL_ALWAYS);
  glDepthMask(GL_TRUE);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDepthFunc(GL_GREATER);
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

void GlScene::render_view(const glm::mat4& clip, const MirrorView& view, int* views_left) {
  check_deadline();
  exact_stats_.deepest_level = std::max(exact_stats_.deepest_level, view.level);
  Target& t = *target_;
  const GLenum colour[] = {GL_COLOR_ATTACHMENT0};
  auto bind_target = [&] {
    glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    glDrawBuffers(1, colour);
    if (view.level > 0) glEnable(GL_CLIP_DISTANCE0); else glDisable(GL_CLIP_DISTANCE0);
    glEnable(GL_SCISSOR_TEST);
    glScissor(view.scissor.x, view.scissor.y, view.scissor.z, view.scissor.w);
  };
  // 1. The view's depth.
  bind_target();
  stencil_level(view.level);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthFunc(GL_GREATER);
  draw_scene(*depth_program_, clip, view);

  // 2. The views behind the mirrors it shows, each drawn into the mirror's region. First
  // which mirrors are a visible surface anywhere in the view (one occlusion query each, read
  // together: one wait for the GL), then each of those in turn.
  std::vector<uint32_t> recursed(reflectors_.reflectors.size() + 1, 0);
  if (exact_stats_.mirrors && view.level < exact_.max_depth) {
    struct Candidate {
      size_t r;
      double side;
      glm::ivec4 bounds;
      GLuint query = 0;
    };
    std::vector<Candidate> candidates;
    for (size_t r = 0; r < reflectors_.reflectors.size(); ++r) {
      const PlanarReflector& mirror = reflectors_.reflectors[r];
      const double side = mirror.side(view.eye);
      if (static_cast<uint32_t>(r + 1) == view.skip || side == 0.0) continue;  // seen through; edge-on covers nothing
      glm::dmat4 linear = view.model;
      linear[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);
      const glm::ivec4 bounds = projected_bounds(*scene_.triangles, mirror.triangles, glm::dmat4(clip) * linear, view.eye,
                                                 view.scissor, t.width, t.height);
      if (bounds.z <= 0 || bounds.w <= 0) {
        ++exact_stats_.mirror_views_empty;
        continue;
      }
      candidates.push_back({r, side, bounds});
    }
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_EQUAL);
    stencil_level(view.level);
    for (Candidate& c : candidates) {
      glGenQueries(1, &c.query);
      glBeginQuery(GL_ANY_SAMPLES_PASSED, c.query);
      draw_reflector(*depth_program_, clip, view, c.r);
      glEndQuery(GL_ANY_SAMPLES_PASSED);
    }
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_GREATER);
    for (Candidate& c : candidates) {
      GLuint marked = 0;
      glGetQueryObjectuiv(c.query, GL_QUERY_RESULT, &marked);
      glDeleteQueries(1, &c.query);
      if (!marked) {
        ++exact_stats_.mirror_views_empty;
        continue;
      }
      if (*views_left <= 0) {  // this mirror shows the environment map, as the envmap method would
        ++exact_stats_.mirror_views_over_budget;
        continue;
      }
      const PlanarReflector& mirror = reflectors_.reflectors[c.r];
      const uint32_t id = static_cast<uint32_t>(c.r + 1);
      --*views_left;
      ++exact_stats_.mirror_views;
      recursed[id] = 1;
      // Mark where it is the visible surface: stencil L -> L + 1.
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      glDepthMask(GL_FALSE);
      glDepthFunc(GL_EQUAL);
      glStencilFunc(GL_EQUAL, view.level, 0xff);
      glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
      draw_reflector(*depth_program_, clip, view, c.r);
      glDepthMask(GL_TRUE);
      glDepthFunc(GL_GREATER);
      // Its region cleared to the background at the far plane, then the view behind it.
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      MirrorView behind;
      behind.level = view.level + 1;
      const glm::dmat4 reflect = reflection_matrix(mirror.normal, mirror.offset);
      behind.model = view.model * reflect;
      behind.eye = glm::dvec3(reflect * glm::dvec4(view.eye, 1.0));
      behind.plane = (c.side > 0 ? 1.0 : -1.0) * glm::dvec4(mirror.normal, mirror.offset);
      behind.skip = id;
      behind.scissor = c.bounds;
      glScissor(c.bounds.x, c.bounds.y, c.bounds.z, c.bounds.w);
      fill_region(view.level + 1, glm::vec4(glm::vec3(scene_.background), 0.f));
      render_view(clip, behind, views_left);
      // The mirror's depth back over its region, and the stencil back to L.
      bind_target();
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      glStencilFunc(GL_EQUAL, view.level + 1, 0xff);
      glStencilOp(GL_KEEP, GL_KEEP, GL_DECR);
      glDepthFunc(GL_ALWAYS);
      draw_reflector(*depth_program_, clip, view, c.r);
      glDepthFunc(GL_GREATER);
      stencil_level(view.level);
    }
  }
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);

  // 3. The view's shadow-volume counts, from its depth.
  const bool volumes = exact_stats_.volumes && !volume_lights_.empty();
  if (volumes) count_volumes(clip, view);

  // 4. Its colour: the visible surfaces (depth EQUAL: the same vertex stage as the depth
  // pass, invariant; the mirror the view is seen through, left out of that pass, fails it;
  // no discard, so the fragments behind are dropped before they are shaded), a mirror drawn
  // behind blended over.
  bind_target();
  stencil_level(view.level);
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  upload_lights(view.eye);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, recursed_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(recursed.size() * sizeof(uint32_t)), recursed.data(),
               GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, recursed_);
  exact_program_->use();
  glUniform1i(exact_program_->uniform("u_volumes"), volumes);
  glUniform1i(exact_program_->uniform("u_bounces_left"), view.level < exact_.max_depth);
  glUniform1i(exact_program_->uniform("u_shadows_approximate"), shadows_approximate_);
  glUniform1i(exact_program_->uniform("u_environment"), environment_ != 0 && view.level < exact_.max_depth);
  glActiveTexture(GL_TEXTURE0 + VOLUME_COUNT_UNIT);
  glBindTexture(GL_TEXTURE_2D_ARRAY, volumes ? exact_buffers_->counts : 0);
  glActiveTexture(GL_TEXTURE0);
  if (shade_pixels()) {
    shade_groups(clip, view, volumes);
    return;
  }
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_SRC1_COLOR);
  draw_scene(*exact_program_, clip, view);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
}

// The view's colour shaded once a pixel and surface (ExactCameraOptions::Shading::pixels):
// its visible triangle at each sample of its stencil region (camera_ids.frag), then one
// fragment a pixel of its scissor groups the samples and shades each group
// (camera_groups.frag), blending over the target's texels itself. Called from render_view's
// step 4, with the target bound, its state set and the lights uploaded; leaves the depth
// and stencil tests on and the target's viewport, as that step does.
void GlScene::shade_groups(const glm::mat4& clip, const MirrorView& view, bool volumes) {
  Target& t = *target_;
  if (!visibility_ || visibility_->width != t.width || visibility_->height != t.height) {
    visibility_.reset();
    visibility_ = std::make_unique<VisibilityBuffers>(t);
  }
  VisibilityBuffers& v = *visibility_;
  // The view's scissor grown to whole pixels: the second pass reads every sample of a pixel,
  // so the keys of those outside the view's scissor are cleared too (the stencil keeps the
  // view's own samples within it).
  const int x0 = view.scissor.x / MASK_COLUMNS, y0 = view.scissor.y / MASK_ROWS;
  const int x1 = (view.scissor.x + view.scissor.z + MASK_COLUMNS - 1) / MASK_COLUMNS;
  const int y1 = (view.scissor.y + view.scissor.w + MASK_ROWS - 1) / MASK_ROWS;
  // 1. Which triangle each sample of the view shows, and its volume lights' set.
  glBindFramebuffer(GL_FRAMEBUFFER, v.fbo);
  glScissor(x0 * MASK_COLUMNS, y0 * MASK_ROWS, (x1 - x0) * MASK_COLUMNS, (y1 - y0) * MASK_ROWS);
  const GLenum first[] = {GL_COLOR_ATTACHMENT0};
  glDrawBuffers(1, first);
  const GLuint none[4] = {0, 0, 0, 0};
  glClearBufferuiv(GL_COLOR, 0, none);
  stencil_level(view.level);
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  ids_program_->use();
  glUniform1i(ids_program_->uniform("u_volume_layers"), volumes ? exact_buffers_->layers : 0);
  draw_scene(*ids_program_, clip, view);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);

  // 2. One fragment a pixel of the scissor.
  glBindFramebuffer(GL_FRAMEBUFFER, v.pixels_fbo);
  glViewport(0, 0, t.width / MASK_COLUMNS, t.height / MASK_ROWS);
  glScissor(x0, y0, x1 - x0, y1 - y0);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_CLIP_DISTANCE0);
  const GlProgram& p = *groups_program_;
  set_view(p, clip, view);
  glm::dmat4 linear = view.model;
  linear[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);
  const glm::mat4 unproject(glm::inverse(glm::dmat4(clip) * linear));
  glUniformMatrix4fv(p.uniform("u_unproject"), 1, GL_FALSE, &unproject[0][0]);
  glUniform2f(p.uniform("u_grid"), float(t.width), float(t.height));
  glUniform1i(p.uniform("u_volumes"), volumes);
  glUniform1i(p.uniform("u_bounces_left"), view.level < exact_.max_depth);
  glUniform1i(p.uniform("u_shadows_approximate"), shadows_approximate_);
  glUniform1i(p.uniform("u_environment"), environment_ != 0 && view.level < exact_.max_depth);
  glUniform1i(p.uniform("u_uvs"), uv_vbo_ != 0);
  glUniform1i(p.uniform("u_portals"), portal_vbo_ != 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, POSITIONS_BINDING, positions_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, UVS_BINDING, uv_vbo_ != 0 ? uv_vbo_ : positions_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, PORTALS_BINDING, portal_vbo_ != 0 ? portal_vbo_ : positions_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, NORMALS_BINDING, normals_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, TRIANGLE_MATERIALS_BINDING, material_ids_);
  glUniform1i(p.uniform("u_pixels"), view.level == 0);
  glBindImageTexture(0, t.color0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, v.pixel_color, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(2, v.pixel_weight, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, v.ids);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindTexture(GL_TEXTURE_2D, 0);
  // Its image stores seen by what follows: blending, the parent view's passes, the resolve.
  glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  for (GLuint unit = 0; unit < 3; ++unit) glBindImageTexture(unit, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glViewport(0, 0, t.width, t.height);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_STENCIL_TEST);
}

void GlScene::make_exact_programs() {
  if (exact_program_) return;
  const std::vector<const char*> scene_vert = scene_vertex_stage(), fill_vert{"fill.vert"};
  exact_program_ = std::make_unique<GlProgram>(
      scene_vert, std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "camera_surface.glsl", "camera_exact.frag"});
  groups_program_ = std::make_unique<GlProgram>(
      fill_vert, std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "camera_surface.glsl", "camera_groups.frag"});
  ids_program_ = std::make_unique<GlProgram>(scene_vert, std::vector<const char*>{"camera_ids.frag"});
  depth_program_ = std::make_unique<GlProgram>(scene_vert, std::vector<const char*>{"camera_depth.frag"});
  probe_program_ = std::make_unique<GlProgram>(
      scene_vert, std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "shadow_probe.frag"});
  for (const GlProgram* p : {exact_program_.get(), probe_program_.get(), groups_program_.get(), ids_program_.get()}) {
    p->use();
    glUniform1i(p->uniform("u_volume_counts"), static_cast<GLint>(VOLUME_COUNT_UNIT));
  }
  groups_program_->use();
  glUniform1i(groups_program_->uniform("u_keys"), 0);
  fill_program_ = std::make_unique<GlProgram>(fill_vert, std::vector<const char*>{"fill.frag"});
  volume_program_ =
      std::make_unique<GlProgram>(scene_vertex_stage("volume_caps.glsl"), std::vector<const char*>{"shadow_volume.frag"});
  resolve_program_ = std::make_unique<GlProgram>(fill_vert, std::vector<const char*>{"resolve_samples.frag"});
  glGenBuffers(1, &recursed_);
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

Image GlScene::camera_color_exact(const Camera& camera) {
  const int64_t full_w = int64_t{camera.width} * MASK_COLUMNS, full_h = int64_t{camera.height} * MASK_ROWS;
  const SampleTiles tiles(full_w, full_h, max_size_);
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  Target& t = target(tiles.target_w(), tiles.target_h(), false);
  make_exact_programs();
  if (exact_stats_.volumes) {
    if (!volumes_built_) build_volumes();
    for (size_t i = 0; i < scene_.lights.size(); ++i) {
      shadows_approximate_ = shadows_approximate_ || (scene_.lights[i].cast_shadows && volume_bit_[i] < 0);
    }
    if (!exact_buffers_ || exact_buffers_->width != t.width || exact_buffers_->height != t.height ||
      exact_buffers_->layers != static_cast<int>(volume_lights_.size())) {
      exact_buffers_.reset();
      exact_buffers_ = std::make_unique<ExactBuffers>(t, static_cast<int>(volume_lights_.size()));
    }
  }
  exact_stats_.shading_pixels = false;
  exact_stats_.shading_why = "asked: --gpu-shading samples";
  if (exact_.shading == ExactCameraOptions::Shading::pixels) {
    exact_stats_.shading_why = shade_pixels_why_not();
    exact_stats_.shading_pixels = exact_stats_.shading_why.empty();
  }
  for (const GlProgram* p : {groups_program_.get(), exact_program_.get()}) {
    bind_lookups(*p, true);
    glUniform1i(p->uniform("u_portals_exact"), 1);
  }
  const glm::mat4 clip = relative_camera_clip(camera, near_);
  std::vector<float> rgba(static_cast<size_t>(tile_w / MASK_COLUMNS) * static_cast<size_t>(tile_h / MASK_ROWS) * 4);
  Image out(camera.width, camera.height, 3);
  exact_pixels_.assign(static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height), 1);
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      Clock::time_point t0 = Clock::now();
      t.clear(scene_.background);
      const float background[4] = {float(scene_.background.x), float(scene_.background.y), float(scene_.background.z), 0.f};
      glClearBufferfv(GL_COLOR, 0, background);  // alpha: no approximated surface yet
      MirrorView camera_view;
      camera_view.eye = camera.position;
      camera_view.scissor = glm::ivec4(0, 0, t.width, t.height);
      int views_left = exact_.max_views;
      render_view(tiles.matrix(x0, y0) * clip, camera_view, &views_left);
      glDisable(GL_STENCIL_TEST);
      glDisable(GL_CLIP_DISTANCE0);
      glDisable(GL_SCISSOR_TEST);
      glFinish();
      timings_.camera_ms += ms_since(t0);
      t0 = Clock::now();
      // The box filter of each pixel's 32 samples on the GPU, then the tile's pixels read
      // back (GL's row 0 is the bottom; the image's row 0 is the top).
      const int pw = tile_w / MASK_COLUMNS, ph = tile_h / MASK_ROWS;
      if (resolve_w_ != pw || resolve_h_ != ph) {
        glDeleteTextures(1, &resolve_texture_);
        glGenTextures(1, &resolve_texture_);
        glBindTexture(GL_TEXTURE_2D, resolve_texture_);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, pw, ph);
        if (!resolve_fbo_) glGenFramebuffers(1, &resolve_fbo_);
        glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, resolve_texture_, 0);
        resolve_w_ = pw;
        resolve_h_ = ph;
      }
      const GLenum first[] = {GL_COLOR_ATTACHMENT0};
      glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
      glDrawBuffers(1, first);
      glViewport(0, 0, pw, ph);
      glDisable(GL_DEPTH_TEST);
      resolve_program_->use();
      glUniform1i(resolve_program_->uniform("u_samples"), 0);
      glUniform2i(resolve_program_->uniform("u_margin"), SampleTiles::MARGIN_X, SampleTiles::MARGIN_Y);
      // Per-pixel shading: the camera view's pixels shaded whole (camera_groups.frag).
      const bool pixels = shade_pixels() && visibility_;
      glUniform1i(resolve_program_->uniform("u_pixels"), pixels);
      glUniform1i(resolve_program_->uniform("u_pixel_color"), 1);
      glUniform1i(resolve_program_->uniform("u_pixel_weight"), 2);
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, pixels ? visibility_->pixel_color : 0);
      glActiveTexture(GL_TEXTURE2);
      glBindTexture(GL_TEXTURE_2D, pixels ? visibility_->pixel_weight : 0);
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, t.color0);
      glBindVertexArray(vao_);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      glBindTexture(GL_TEXTURE_2D, 0);
      for (const GLenum unit : {GL_TEXTURE1, GL_TEXTURE2}) {
        glActiveTexture(unit);
        glBindTexture(GL_TEXTURE_2D, 0);
      }
      glActiveTexture(GL_TEXTURE0);
      glEnable(GL_DEPTH_TEST);
      glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
      glReadBuffer(GL_COLOR_ATTACHMENT0);
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, pw, ph, GL_RGBA, GL_FLOAT, rgba.data());
      for (int64_t py = 0; py < ph && y0 + MASK_ROWS * py < full_h; ++py) {
        const size_t row = static_cast<size_t>((full_h - 1 - (y0 + MASK_ROWS * py)) / MASK_ROWS);
        for (int64_t px = 0; px < pw && x0 + MASK_COLUMNS * px < full_w; ++px) {
          const size_t k = static_cast<size_t>(py * pw + px);
          const size_t pixel = row * static_cast<size_t>(camera.width) + static_cast<size_t>(x0 / MASK_COLUMNS + px);
          for (int c = 0; c < 3; ++c) out.data[pixel * 3 + static_cast<size_t>(c)] = rgba[4 * k + static_cast<size_t>(c)];
          exact_stats_.samples_approximate += static_cast<uint64_t>(rgba[4 * k + 3]);
          if (rgba[4 * k + 3] != 0.f) exact_pixels_[pixel] = 0;
        }
      }
      timings_.readback_ms += ms_since(t0);
    }
  }
  // The state the other passes expect back (Mesa refuses a draw to two buffers while the
  // blend function names the second source, even with blending off).
  glActiveTexture(GL_TEXTURE0 + VOLUME_COUNT_UNIT);
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  glActiveTexture(GL_TEXTURE0);
  glBlendFunc(GL_ONE, GL_ZERO);
  glLogicOp(GL_COPY);
  glStencilFunc(GL_ALWAYS, 0, 0xff);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, 0);
  camera_layers_ = 1;
  camera_layers_capped_ = false;
  exact_stats_.pixels_exact = static_cast<uint64_t>(std::count(exact_pixels_.begin(), exact_pixels_.end(), 1));
  check_gl("exact camera pass");
  return out;
}

}  // namespace abcube
