// The exact camera pass's colour shaded once a pixel and surface (ExactCameraOptions::Shading::pixels;
// docs/design/camera-groups.md): GlScene::shade_groups and when it applies.
#include "gl/gl_passes.hpp"

#include <cstdint>
#include <memory>
#include <string>

#include "gl/gl_passes_internal.hpp"
#include "base/samples.hpp"

namespace abcube {

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

}  // namespace abcube
