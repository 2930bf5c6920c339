// abcube crosscheck's shadow probe (gl_shadow_probe.hpp): the shadow volumes' answer and the
// shadow maps' at each camera sample, side by side.
#include "gl/gl_shadow_probe.hpp"

#include <memory>
#include <vector>

#include "base/parallel.hpp"
#include "base/samples.hpp"
#include "gl/gl_scene_parts.hpp"

namespace abcube {

namespace {

// The probe's programs: the camera's depth, then the two answers at the visible surface.
struct ProbePrograms {
  std::unique_ptr<GlProgram> depth, probe;
  explicit ProbePrograms(const GlSceneBuffers& buffers) {
    const std::vector<const char*> scene_vert = buffers.vertex_stage();
    depth = std::make_unique<GlProgram>(scene_vert, std::vector<const char*>{"camera_depth.frag"});
    probe = std::make_unique<GlProgram>(
        scene_vert, std::vector<const char*>{"common_scene.glsl", "common_shading.glsl", "shadow_probe.frag"});
    probe->use();
    glUniform1i(probe->uniform("u_volume_counts"), static_cast<GLint>(VOLUME_COUNT_UNIT));
  }
};

// One tile's probe drawn into the target through `clip` (the tile's), its answers read back.
void probe_tile(GlSceneParts& parts, const ProbePrograms& programs, const glm::mat4& clip, const MirrorView& view,
                const std::vector<GLint>& probe, std::vector<float>* rgba) {
  GlTarget& t = parts.current_target();
  t.clear(parts.scene.background);
  const float none[4] = {0, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, none);
  stencil_level(0);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  parts.buffers.draw_scene(*programs.depth, clip, view);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  if (!parts.volumes.lights().empty()) parts.volumes.count(clip, view);
  const GLenum colour[] = {GL_COLOR_ATTACHMENT0};
  glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  glDrawBuffers(1, colour);
  stencil_level(0);
  glDepthFunc(GL_GEQUAL);
  parts.bind_lookups(*programs.probe, false);
  parts.upload_lights(view.eye);
  programs.probe->use();
  glUniform1iv(programs.probe->uniform("u_probe"), 64, probe.data());
  glActiveTexture(GL_TEXTURE0 + VOLUME_COUNT_UNIT);
  glBindTexture(GL_TEXTURE_2D_ARRAY, parts.volumes.counts());
  glActiveTexture(GL_TEXTURE0);
  parts.buffers.draw_scene(*programs.probe, clip, view);
  glDepthFunc(GL_GREATER);
  glFinish();
  t.read(0, GL_RGBA, GL_FLOAT, rgba->data());
}

}  // namespace

GlShadowProbe probe_camera_shadows(GlScene& gl, const Camera& camera) {
  constexpr int PROBED = 16;
  GlSceneParts& parts = gl.parts();
  const SceneData& scene = parts.scene;
  GlShadowProbe out;
  std::vector<GLint> probe(64, -1);
  for (size_t i = 0; i < scene.lights.size() && out.lights.size() < size_t{PROBED}; ++i) {
    if (!scene.lights[i].cast_shadows) continue;
    if (i < probe.size()) probe[i] = static_cast<GLint>(out.lights.size());
    out.lights.push_back(static_cast<int>(i));
  }
  const int64_t full_w = int64_t{camera.width} * MASK_COLUMNS, full_h = int64_t{camera.height} * MASK_ROWS;
  const SampleTiles tiles(full_w, full_h, parts.buffers.max_size());
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  GlTarget& t = parts.target(tiles.target_w(), tiles.target_h(), false);
  const ProbePrograms programs(parts.buffers);
  parts.volumes.build();
  parts.volumes.attach(t);
  const glm::mat4 clip = relative_camera_clip(camera, parts.buffers.near_distance());
  const size_t grid = static_cast<size_t>(full_w * full_h);
  out.volume.assign(grid, 0);
  out.map.assign(grid, 0);
  out.lit.assign(grid, 0);
  std::vector<float> rgba(static_cast<size_t>(t.width) * static_cast<size_t>(t.height) * 4);
  MirrorView view;
  view.eye = camera.position;
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      probe_tile(parts, programs, tiles.matrix(x0, y0) * clip, view, probe, &rgba);
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
