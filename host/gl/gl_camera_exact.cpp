// The exact camera pass (GlExactCamera): its plan, the views through the planar mirrors, the
// colour of each view, and the GPU's box filter of each pixel's samples.
#include "gl/gl_camera_exact.hpp"

#include <glad/gl.h>

#include <algorithm>
#include <string>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/samples.hpp"
#include "base/timer.hpp"
#include "gl/gl_targets.hpp"
#include "gl/gl_scene_parts.hpp"
#include "gl/gl_shading_groups.hpp"

namespace abcube {

GlExactCamera::GlExactCamera(GlSceneParts& parts) : parts_(parts), mirrors_(parts.buffers) {}

GlExactCamera::~GlExactCamera() {
  groups_.reset();
  glDeleteBuffers(1, &recursed_);
  glDeleteTextures(1, &resolve_texture_);
  glDeleteFramebuffers(1, &resolve_fbo_);
}

std::string GlExactCamera::mirrors_why_not() const {
  if (mirrors_.reflectors().reflectors.empty()) return "no planar reflector";
  if (options_.max_depth <= 0) return "max_depth 0: no reflected ray";
  return "";
}

bool GlExactCamera::plan() {
  const SceneData& scene = parts_.scene;
  ExactCameraStats& s = stats_;
  s.mirrors = s.volumes = s.plain = false;
  s.mirrors_why = s.volumes_why = "";
  s.mirror_views = s.mirror_views_empty = s.mirror_views_over_budget = 0;
  s.samples_approximate = s.pixels_exact = 0;
  s.deepest_level = 0;
  s.reflectors = mirrors_.reflectors().reflectors.size();
  s.curved_reflective_triangles = mirrors_.reflectors().curved_triangles;
  if (!options_.planar_mirrors && !options_.shadow_volumes && !options_.always) return false;
  std::string both;
  for (const uint32_t id : scene.triangles->material_id) {
    if (scene.materials[id].opacity < 1.0) both = "coverage transparency (the peeled camera pass)";
  }
  GLint units = 0, dual = 0;
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
  glGetIntegerv(GL_MAX_DUAL_SOURCE_DRAW_BUFFERS, &dual);
  if (units <= static_cast<GLint>(VOLUME_COUNT_UNIT) || dual < 1) {
    both = "this GL offers " + std::to_string(units) + " texture units and " + std::to_string(dual) +
           " dual-source draw buffers (17 and 1 needed)";
  }
  bool casts = false;
  for (const PointLight& l : scene.lights) casts = casts || l.cast_shadows;

  if (options_.planar_mirrors) {
    s.mirrors_why = both.empty() ? mirrors_why_not() : both;
    s.mirrors = s.mirrors_why.empty();
  }
  if (options_.shadow_volumes) {
    s.volumes_why = !both.empty() ? both : casts ? parts_.volumes.why_not() : "no light casts shadows";
    s.volumes = s.volumes_why.empty();
  }
  // What the pass leaves approximate in every lit sample: shadows by maps (and lights past
  // the volumes' counts: prepare(), once the volumes are built).
  shadows_approximate_ = casts && !s.volumes;
  s.plain = !s.mirrors && !s.volumes && options_.always && both.empty();
  return s.mirrors || s.volumes || s.plain;
}

void GlExactCamera::make_programs() {
  if (exact_program_) return;
  const GlSceneBuffers& buffers = parts_.buffers;
  const std::vector<const char*> scene_vert = buffers.vertex_stage(), fill_vert{"fill.vert"};
  exact_program_ = std::make_unique<GlProgram>(
      scene_vert,
      std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "camera_surface.glsl", "camera_exact.frag"});
  exact_program_->use();
  glUniform1i(exact_program_->uniform("u_volume_counts"), static_cast<GLint>(VOLUME_COUNT_UNIT));
  groups_ = std::make_unique<GlShadingGroups>(buffers);
  depth_program_ = std::make_unique<GlProgram>(scene_vert, std::vector<const char*>{"camera_depth.frag"});
  fill_program_ = std::make_unique<GlProgram>(fill_vert, std::vector<const char*>{"fill.frag"});
  resolve_program_ = std::make_unique<GlProgram>(fill_vert, std::vector<const char*>{"resolve_samples.frag"});
  glGenBuffers(1, &recursed_);
}

// The programs, the volumes and their counts beside `target`, the way the colour is shaded,
// and the lookups of both colour programs.
void GlExactCamera::prepare(const GlTarget& target) {
  make_programs();
  GlShadowVolumes& volumes = parts_.volumes;
  if (stats_.volumes) {
    volumes.build();
    for (size_t i = 0; i < parts_.scene.lights.size(); ++i) {
      shadows_approximate_ =
          shadows_approximate_ || (parts_.scene.lights[i].cast_shadows && volumes.opaque_bit()[i] < 0);
    }
    volumes.attach(target);
    stats_.volume_lights = static_cast<int>(volumes.lights().size());
    stats_.volume_triangles = volumes.triangle_count();
    stats_.volume_build_ms = volumes.build_ms();
  }
  stats_.shading_pixels = false;
  stats_.shading_why = "asked: --gpu-shading samples";
  if (options_.shading == ExactCameraOptions::Shading::pixels) {
    stats_.shading_why = GlShadingGroups::why_not(volumes.lights().size(), parts_.buffers.vertex_count());
    stats_.shading_pixels = stats_.shading_why.empty();
  }
  for (const GlProgram* p : {&groups_->program(), static_cast<const GlProgram*>(exact_program_.get())}) {
    parts_.bind_lookups(*p, true);
    glUniform1i(p->uniform("u_portals_exact"), 1);
  }
}

Image GlExactCamera::render(const Camera& camera) {
  const SceneData& scene = parts_.scene;
  const int64_t full_w = int64_t{camera.width} * MASK_COLUMNS, full_h = int64_t{camera.height} * MASK_ROWS;
  const SampleTiles tiles(full_w, full_h, parts_.buffers.max_size());
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  GlTarget& t = parts_.target(tiles.target_w(), tiles.target_h(), false);
  prepare(t);
  const glm::mat4 clip = relative_camera_clip(camera, parts_.buffers.near_distance());
  const int pw = tile_w / MASK_COLUMNS, ph = tile_h / MASK_ROWS;
  std::vector<float> rgba(static_cast<size_t>(pw) * static_cast<size_t>(ph) * 4);
  Image out(camera.width, camera.height, 3);
  pixels_.assign(static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height), 1);
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      Clock::time_point t0 = Clock::now();
      t.clear(scene.background);
      const float background[4] = {float(scene.background.x), float(scene.background.y), float(scene.background.z),
                                   0.f};
      glClearBufferfv(GL_COLOR, 0, background);  // alpha: no approximated surface yet
      MirrorView camera_view;
      camera_view.eye = camera.position;
      camera_view.scissor = glm::ivec4(0, 0, t.width, t.height);
      int views_left = options_.max_views;
      render_view(tiles.matrix(x0, y0) * clip, camera_view, &views_left);
      glDisable(GL_STENCIL_TEST);
      glDisable(GL_CLIP_DISTANCE0);
      glDisable(GL_SCISSOR_TEST);
      glFinish();
      parts_.timings.camera_ms += ms_since(t0);
      t0 = Clock::now();
      resolve_tile(t, pw, ph, &rgba);
      // GL's row 0 is the bottom; the image's row 0 is the top.
      for (int64_t py = 0; py < ph && y0 + MASK_ROWS * py < full_h; ++py) {
        const size_t row = static_cast<size_t>((full_h - 1 - (y0 + MASK_ROWS * py)) / MASK_ROWS);
        for (int64_t px = 0; px < pw && x0 + MASK_COLUMNS * px < full_w; ++px) {
          const size_t k = static_cast<size_t>(py * pw + px);
          const size_t pixel = row * static_cast<size_t>(camera.width) + static_cast<size_t>(x0 / MASK_COLUMNS + px);
          for (size_t c = 0; c < 3; ++c) out.data[pixel * 3 + c] = rgba[4 * k + c];
          stats_.samples_approximate += static_cast<uint64_t>(rgba[4 * k + 3]);
          if (rgba[4 * k + 3] != 0.f) pixels_[pixel] = 0;
        }
      }
      parts_.timings.readback_ms += ms_since(t0);
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
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, RECURSED_BINDING, 0);
  stats_.pixels_exact = static_cast<uint64_t>(std::count(pixels_.begin(), pixels_.end(), 1));
  check_gl("exact camera pass");
  return out;
}

// The box filter of each pixel's 32 samples of the tile on the GPU, its pw x ph pixels read
// back into `rgba` (GL row order; alpha: the samples that met an approximated surface).
void GlExactCamera::resolve_tile(const GlTarget& t, int pw, int ph, std::vector<float>* rgba) {
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
  const bool pixels = stats_.shading_pixels && groups_->pixel_color() != 0;
  glUniform1i(resolve_program_->uniform("u_pixels"), pixels);
  glUniform1i(resolve_program_->uniform("u_pixel_color"), 1);
  glUniform1i(resolve_program_->uniform("u_pixel_weight"), 2);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, pixels ? groups_->pixel_color() : 0);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_2D, pixels ? groups_->pixel_weight() : 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, t.color0);
  parts_.buffers.bind_vertex_array();
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
  glReadPixels(0, 0, pw, ph, GL_RGBA, GL_FLOAT, rgba->data());
}

// Fills the region of stencil level `level` of the bound framebuffer's first attachment
// with `colour` and its depth with the far plane (fill.vert).
void GlExactCamera::fill_region(int level, const glm::vec4& colour) {
  fill_program_->use();
  glUniform4f(fill_program_->uniform("u_fill"), colour.r, colour.g, colour.b, colour.a);
  stencil_level(level);
  glDepthFunc(GL_ALWAYS);
  glDepthMask(GL_TRUE);
  parts_.buffers.bind_vertex_array();
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDepthFunc(GL_GREATER);
}

// The camera target bound for `view`: its first attachment, its mirror's clip plane (a
// virtual view), its scissor.
void GlExactCamera::bind_view(const MirrorView& view) const {
  const GLenum colour[] = {GL_COLOR_ATTACHMENT0};
  glBindFramebuffer(GL_FRAMEBUFFER, parts_.current_target().fbo);
  glDrawBuffers(1, colour);
  if (view.level > 0)
    glEnable(GL_CLIP_DISTANCE0);
  else
    glDisable(GL_CLIP_DISTANCE0);
  glEnable(GL_SCISSOR_TEST);
  glScissor(view.scissor.x, view.scissor.y, view.scissor.z, view.scissor.w);
}

void GlExactCamera::render_view(const glm::mat4& clip, const MirrorView& view, int* views_left) {
  check_deadline();
  stats_.deepest_level = std::max(stats_.deepest_level, view.level);
  // 1. The view's depth.
  bind_view(view);
  stencil_level(view.level);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthFunc(GL_GREATER);
  parts_.buffers.draw_scene(*depth_program_, clip, view);
  // 2. The views behind the mirrors it shows, each drawn into the mirror's region.
  std::vector<uint32_t> recursed(mirrors_.reflectors().reflectors.size() + 1, 0);
  if (stats_.mirrors && view.level < options_.max_depth) draw_mirror_views(clip, view, views_left, &recursed);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  // 3. The view's shadow-volume counts, from its depth.
  if (view_shading(view).volumes) parts_.volumes.count(clip, view);
  // 4. Its colour.
  shade_view(clip, view, recursed);
}

// Which mirrors are a visible surface anywhere in the view (one occlusion query each, read
// together: one wait for the GL), then the view behind each of those in turn, while the
// budget of views lasts; `recursed` marks the mirrors drawn (reflector + 1).
void GlExactCamera::draw_mirror_views(const glm::mat4& clip, const MirrorView& view, int* views_left,
                                      std::vector<uint32_t>* recursed) {
  struct Candidate {
    size_t r;
    double side;
    glm::ivec4 bounds;
    GLuint query = 0;
  };
  const GlTarget& t = parts_.current_target();
  std::vector<Candidate> candidates;
  for (size_t r = 0; r < mirrors_.reflectors().reflectors.size(); ++r) {
    const double side = mirrors_.reflectors().reflectors[r].side(view.eye);
    if (static_cast<uint32_t>(r + 1) == view.skip || side == 0.0) continue;  // seen through; edge-on covers nothing
    const glm::ivec4 bounds = mirrors_.bounds(r, clip, view, t.width, t.height);
    if (bounds.z <= 0 || bounds.w <= 0) {
      ++stats_.mirror_views_empty;
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
    mirrors_.draw(*depth_program_, clip, view, c.r);
    glEndQuery(GL_ANY_SAMPLES_PASSED);
  }
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
  for (Candidate& c : candidates) {
    GLuint marked = 0;
    glGetQueryObjectuiv(c.query, GL_QUERY_RESULT, &marked);
    glDeleteQueries(1, &c.query);
    if (!marked) {
      ++stats_.mirror_views_empty;
      continue;
    }
    if (*views_left <= 0) {  // this mirror shows the environment map, as the envmap method would
      ++stats_.mirror_views_over_budget;
      continue;
    }
    --*views_left;
    ++stats_.mirror_views;
    (*recursed)[c.r + 1] = 1;
    draw_behind_mirror(clip, view, c.r, c.side, c.bounds, views_left);
  }
}

// Mirror r's samples where it is the visible surface of `view` go to the next stencil level,
// cleared to the background at the far plane; the view behind it is drawn there; then the
// mirror's depth goes back over its region and the stencil back to the view's level.
void GlExactCamera::draw_behind_mirror(const glm::mat4& clip, const MirrorView& view, size_t r, double side,
                                       const glm::ivec4& bounds, int* views_left) {
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glDepthFunc(GL_EQUAL);
  glStencilFunc(GL_EQUAL, view.level, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  mirrors_.draw(*depth_program_, clip, view, r);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glScissor(bounds.x, bounds.y, bounds.z, bounds.w);
  fill_region(view.level + 1, glm::vec4(glm::vec3(parts_.scene.background), 0.f));
  render_view(clip, mirrors_.behind(r, view, side, bounds), views_left);
  bind_view(view);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glStencilFunc(GL_EQUAL, view.level + 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_DECR);
  glDepthFunc(GL_ALWAYS);
  mirrors_.draw(*depth_program_, clip, view, r);
  glDepthFunc(GL_GREATER);
  stencil_level(view.level);
}

ViewShading GlExactCamera::view_shading(const MirrorView& view) const {
  ViewShading s;
  s.volumes = stats_.volumes && !parts_.volumes.lights().empty();
  s.volume_layers = static_cast<int>(parts_.volumes.lights().size());
  s.bounces_left = view.level < options_.max_depth;
  s.shadows_approximate = shadows_approximate_;
  s.environment = parts_.environment.built() && view.level < options_.max_depth;
  return s;
}

// The view's colour: its visible surfaces (depth EQUAL: the same vertex stage as the depth
// pass, invariant; the mirror the view is seen through, left out of that pass, fails it; no
// discard, so the fragments behind are dropped before they are shaded), a mirror drawn
// behind blended over.
void GlExactCamera::shade_view(const glm::mat4& clip, const MirrorView& view, const std::vector<uint32_t>& recursed) {
  const ViewShading shading = view_shading(view);
  bind_view(view);
  stencil_level(view.level);
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  parts_.upload_lights(view.eye);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, recursed_);
  glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(recursed.size() * sizeof(uint32_t)), recursed.data(),
               GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, RECURSED_BINDING, recursed_);
  shading.set(*exact_program_);
  glActiveTexture(GL_TEXTURE0 + VOLUME_COUNT_UNIT);
  glBindTexture(GL_TEXTURE_2D_ARRAY, shading.volumes ? parts_.volumes.counts() : 0);
  glActiveTexture(GL_TEXTURE0);
  if (stats_.shading_pixels) {
    groups_->shade(parts_.current_target(), clip, view, shading, mirrors_.portal_ids());
    return;
  }
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_SRC1_COLOR);
  parts_.buffers.draw_scene(*exact_program_, clip, view);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
}

}  // namespace abcube
