// The exact camera pass's colour shaded once a pixel and surface (GlShadingGroups).
#include "gl/gl_shading_groups.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "base/samples.hpp"
#include "gl/gl_targets.hpp"
#include "gl/gl_scene_buffers.hpp"

namespace abcube {

void ViewShading::set(const GlProgram& program) const {
  program.use();
  glUniform1i(program.uniform("u_volumes"), volumes);
  glUniform1i(program.uniform("u_bounces_left"), bounces_left);
  glUniform1i(program.uniform("u_shadows_approximate"), shadows_approximate);
  glUniform1i(program.uniform("u_environment"), environment);
}

// The buffers beside the camera target: the key of each sample of a view (camera_ids.frag,
// RG32UI, drawn with the target's depth-stencil), and a framebuffer with no attachment, one
// pixel of it per 8 x 4 samples of the target; the colour and weight of the camera view's
// pixels shaded whole (RGBA32F, one texel a pixel).
struct GlShadingGroups::Buffers {
  int width = 0, height = 0;
  GLuint ids = 0, fbo = 0, pixels_fbo = 0, pixel_color = 0, pixel_weight = 0;

  explicit Buffers(const GlTarget& t) : width(t.width), height(t.height) {
    const auto make = [](GLenum format, int w, int h) {
      GLuint tex = 0;
      glGenTextures(1, &tex);
      glBindTexture(GL_TEXTURE_2D, tex);
      glTexStorage2D(GL_TEXTURE_2D, 1, format, w, h);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      return tex;
    };
    ids = make(GL_RG32UI, width, height);
    pixel_color = make(GL_RGBA32F, width / MASK_COLUMNS, height / MASK_ROWS);
    pixel_weight = make(GL_RGBA32F, width / MASK_COLUMNS, height / MASK_ROWS);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, ids, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, t.depth, 0);
    check_framebuffer("visibility");
    glGenFramebuffers(1, &pixels_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, pixels_fbo);
    glFramebufferParameteri(GL_FRAMEBUFFER, GL_FRAMEBUFFER_DEFAULT_WIDTH, width / MASK_COLUMNS);
    glFramebufferParameteri(GL_FRAMEBUFFER, GL_FRAMEBUFFER_DEFAULT_HEIGHT, height / MASK_ROWS);
    check_framebuffer("per-pixel shading");
  }
  ~Buffers() {
    const GLuint textures[] = {ids, pixel_color, pixel_weight};
    glDeleteTextures(3, textures);
    const GLuint fbos[] = {fbo, pixels_fbo};
    glDeleteFramebuffers(2, fbos);
  }
  Buffers(const Buffers&) = delete;
  Buffers& operator=(const Buffers&) = delete;
};

GlShadingGroups::GlShadingGroups(const GlSceneBuffers& buffers) : buffers_(buffers) {
  ids_program_ = std::make_unique<GlProgram>(buffers.vertex_stage(), std::vector<const char*>{"camera_ids.frag"});
  groups_program_ = std::make_unique<GlProgram>(std::vector<const char*>{"fill.vert"},
                                                std::vector<const char*>{"common_scene.glsl", "common_shading.glsl",
                                                                         "camera_surface.glsl", "camera_groups.frag"});
  for (const GlProgram* p : {groups_program_.get(), ids_program_.get()}) {
    p->use();
    glUniform1i(p->uniform("u_volume_counts"), static_cast<GLint>(VOLUME_COUNT_UNIT));
  }
  groups_program_->use();
  glUniform1i(groups_program_->uniform("u_keys"), 0);
}

GlShadingGroups::~GlShadingGroups() = default;

GLuint GlShadingGroups::pixel_color() const { return buffers_of_target_ ? buffers_of_target_->pixel_color : 0; }
GLuint GlShadingGroups::pixel_weight() const { return buffers_of_target_ ? buffers_of_target_->pixel_weight : 0; }

std::string GlShadingGroups::why_not(size_t volume_lights, GLsizei vertex_count) {
  if (volume_lights > 32) {
    return std::to_string(volume_lights) + " volume counts (a sample's key holds 32)";
  }
  GLint64 block = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  const uint64_t bytes = static_cast<uint64_t>(vertex_count) * VERTEX_ARRAY_BYTES;
  if (bytes > static_cast<uint64_t>(block)) {
    return "the vertex positions' " + std::to_string(bytes) + " bytes exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE " +
           std::to_string(block);
  }
  return "";
}

// Which triangle each sample of the view shows, and its volume lights' set, over `pixels`
// (x0, y0, x1, y1 in whole pixels: the second pass reads every sample of a pixel, so the keys
// of those outside the view's scissor are cleared too; the stencil keeps the view's own
// samples within it).
void GlShadingGroups::mark_samples(const glm::mat4& clip, const MirrorView& view, const glm::ivec4& pixels,
                                   int volume_layers) {
  glBindFramebuffer(GL_FRAMEBUFFER, buffers_of_target_->fbo);
  glScissor(pixels.x * MASK_COLUMNS, pixels.y * MASK_ROWS, (pixels.z - pixels.x) * MASK_COLUMNS,
            (pixels.w - pixels.y) * MASK_ROWS);
  const GLenum first[] = {GL_COLOR_ATTACHMENT0};
  glDrawBuffers(1, first);
  const GLuint none[4] = {0, 0, 0, 0};
  glClearBufferuiv(GL_COLOR, 0, none);
  stencil_level(view.level);
  glDepthFunc(GL_EQUAL);
  glDepthMask(GL_FALSE);
  ids_program_->use();
  glUniform1i(ids_program_->uniform("u_volume_layers"), volume_layers);
  buffers_.draw_scene(*ids_program_, clip, view);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
}

void GlShadingGroups::shade(GlTarget& t, const glm::mat4& clip, const MirrorView& view, const ViewShading& shading,
                            GLuint portals) {
  if (!buffers_of_target_ || buffers_of_target_->width != t.width || buffers_of_target_->height != t.height) {
    buffers_of_target_.reset();
    buffers_of_target_ = std::make_unique<Buffers>(t);
  }
  const Buffers& v = *buffers_of_target_;
  // The view's scissor grown to whole pixels.
  const int x0 = view.scissor.x / MASK_COLUMNS, y0 = view.scissor.y / MASK_ROWS;
  const int x1 = (view.scissor.x + view.scissor.z + MASK_COLUMNS - 1) / MASK_COLUMNS;
  const int y1 = (view.scissor.y + view.scissor.w + MASK_ROWS - 1) / MASK_ROWS;
  // 1. Which triangle each sample shows.
  mark_samples(clip, view, glm::ivec4(x0, y0, x1, y1), shading.volumes ? shading.volume_layers : 0);

  // 2. One fragment a pixel of the scissor.
  glBindFramebuffer(GL_FRAMEBUFFER, v.pixels_fbo);
  glViewport(0, 0, t.width / MASK_COLUMNS, t.height / MASK_ROWS);
  glScissor(x0, y0, x1 - x0, y1 - y0);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_CLIP_DISTANCE0);
  const GlProgram& p = *groups_program_;
  buffers_.set_view(p, clip, view);
  const glm::mat4 unproject(glm::inverse(glm::dmat4(clip) * view.linear()));
  glUniformMatrix4fv(p.uniform("u_unproject"), 1, GL_FALSE, &unproject[0][0]);
  glUniform2f(p.uniform("u_grid"), float(t.width), float(t.height));
  shading.set(p);
  const GLuint uvs = buffers_.uvs();
  glUniform1i(p.uniform("u_uvs"), uvs != 0);
  glUniform1i(p.uniform("u_portals"), portals != 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, POSITIONS_BINDING, buffers_.positions());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, UVS_BINDING, uvs != 0 ? uvs : buffers_.positions());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, PORTALS_BINDING, portals != 0 ? portals : buffers_.positions());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, NORMALS_BINDING, buffers_.normals());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, TRIANGLE_MATERIALS_BINDING, buffers_.material_ids());
  glUniform1i(p.uniform("u_pixels"), view.level == 0);
  glBindImageTexture(TARGET_IMAGE, t.color0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(PIXEL_COLOR_IMAGE, v.pixel_color, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(PIXEL_WEIGHT_IMAGE, v.pixel_weight, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, v.ids);
  buffers_.bind_vertex_array();
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindTexture(GL_TEXTURE_2D, 0);
  // Its image stores seen by what follows: blending, the parent view's passes, the resolve.
  glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  for (GLuint unit : {TARGET_IMAGE, PIXEL_COLOR_IMAGE, PIXEL_WEIGHT_IMAGE})
    glBindImageTexture(unit, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glViewport(0, 0, t.width, t.height);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_STENCIL_TEST);
}

}  // namespace abcube
