// The camera pass of the gpu method where the GPU is exact (gl_passes.hpp
// ExactCameraOptions). PLANAR MIRRORS (course notes 4.1.2; Kilgard 1999): the stencil holds
// the mirror level of the view a sample shows; each visible reflector marks its samples,
// clears them, and draws the scene reflected about its plane there (clipped at the mirror,
// recursively to max_depth), so the virtual view is what the reflected rays of those very
// samples meet; the colour pass blends it in, C = C_local + kr * C_behind. SHADOW VOLUMES
// (course notes 3.3; Everitt & Kilgard 2002): per volume light, a depth-fail count of its
// faces at each sample, S_l = 0 where it is not 0 (gl_shadow_volumes.cpp); the colour shaded
// once a pixel and surface is gl_shading_groups.cpp's. docs/design/gl-camera-exact.md has the
// whole argument.
#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_passes.hpp"
#include "gl/gl_passes_internal.hpp"
#include "raster/cube_map.hpp"
#include "base/samples.hpp"

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
// through `clip_model` relative to `eye` (scene.vert), within `parent` (x, y, width, height); the parent itself when
// one of their corners is behind the eye. Empty (zero size) when they fall outside.
glm::ivec4 projected_bounds(const TriangleSoup& soup, const std::vector<uint32_t>& triangles,
                            const glm::dmat4& clip_model, const glm::dvec3& eye, const glm::ivec4& parent, int width,
                            int height) {
  double lo_x = 1e300, lo_y = 1e300, hi_x = -1e300, hi_y = -1e300;
  for (const uint32_t t : triangles) {
    for (size_t k = 0; k < 3; ++k) {
      const glm::dvec4 c =
          clip_model * glm::dvec4(glm::dvec3(soup.positions[3 * static_cast<size_t>(t) + k]) - eye, 1.0);
      if (!(c.w > 0.0)) return parent;
      const double x = (c.x / c.w * 0.5 + 0.5) * width, y = (c.y / c.w * 0.5 + 0.5) * height;
      lo_x = std::min(lo_x, x), lo_y = std::min(lo_y, y), hi_x = std::max(hi_x, x), hi_y = std::max(hi_y, y);
    }
  }
  // One pixel of margin each way: the rasteriser's own rounding.
  const double x0 = std::max(std::floor(lo_x) - 1.0, double(parent.x)),
               y0 = std::max(std::floor(lo_y) - 1.0, double(parent.y));
  const double x1 = std::min(std::ceil(hi_x) + 1.0, double(parent.x + parent.z));
  const double y1 = std::min(std::ceil(hi_y) + 1.0, double(parent.y + parent.w));
  if (!(x1 > x0) || !(y1 > y0)) return glm::ivec4(0);
  return glm::ivec4(int(x0), int(y0), int(x1 - x0), int(y1 - y0));
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

void GlScene::render_view(const glm::mat4& clip, const MirrorView& view, int* views_left) {
  check_deadline();
  exact_stats_.deepest_level = std::max(exact_stats_.deepest_level, view.level);
  Target& t = *target_;
  const GLenum colour[] = {GL_COLOR_ATTACHMENT0};
  auto bind_target = [&] {
    glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    glDrawBuffers(1, colour);
    if (view.level > 0)
      glEnable(GL_CLIP_DISTANCE0);
    else
      glDisable(GL_CLIP_DISTANCE0);
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
      const glm::ivec4 bounds = projected_bounds(*scene_.triangles, mirror.triangles, glm::dmat4(clip) * linear,
                                                 view.eye, view.scissor, t.width, t.height);
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

void GlScene::make_exact_programs() {
  if (exact_program_) return;
  const std::vector<const char*> scene_vert = scene_vertex_stage(), fill_vert{"fill.vert"};
  exact_program_ = std::make_unique<GlProgram>(
      scene_vert,
      std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "camera_surface.glsl", "camera_exact.frag"});
  groups_program_ =
      std::make_unique<GlProgram>(fill_vert, std::vector<const char*>{"common_scene.glsl", "common_shading.glsl",
                                                                      "camera_surface.glsl", "camera_groups.frag"});
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
  volume_program_ = std::make_unique<GlProgram>(scene_vertex_stage("volume_caps.glsl"),
                                                std::vector<const char*>{"shadow_volume.frag"});
  resolve_program_ = std::make_unique<GlProgram>(fill_vert, std::vector<const char*>{"resolve_samples.frag"});
  glGenBuffers(1, &recursed_);
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
      const float background[4] = {float(scene_.background.x), float(scene_.background.y), float(scene_.background.z),
                                   0.f};
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
          for (int c = 0; c < 3; ++c)
            out.data[pixel * 3 + static_cast<size_t>(c)] = rgba[4 * k + static_cast<size_t>(c)];
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
