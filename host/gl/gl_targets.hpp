// What the GL techniques share beneath their front (host/gl/gl_*.cpp): texture units, the
// pass state, the stencil test, the camera's sample tiles, the framebuffers the passes render
// into (gl_targets.cpp), and the view a draw is made through. What the shaders share with
// them: glsl_shared.hpp.
#pragma once
#include <glad/gl.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "base/error.hpp"
#include "gl/gl_types.hpp"
#include "raster/cube_map.hpp"
#include "base/samples.hpp"

namespace abcube {

// The camera pass renders at most this many samples a side at once (tiles beyond). 1024:
// every tile repeats the passes and draw calls of each view, so smaller tiles cost more of
// them; larger ones take more memory, give a mirror's scissor less to cut away, and let the
// tile's buffers fall out of cache. docs/design/decisions.md has the measurements.
constexpr int CAMERA_TILE = 1024;
// The largest of the scene's per-vertex arrays, which camera_groups.frag reads as storage
// buffers: a position or a normal (3 floats; a vertex's ids are 2 words).
constexpr size_t VERTEX_ARRAY_BYTES = 12;
// Texture units: 1 the opaque shadow maps, 2 the environment, 3.. the translucent peels,
// then the camera's previous layer.
constexpr GLenum PEEL_UNIT = 3;
constexpr GLenum CAMERA_PREVIOUS_UNIT = PEEL_UNIT + MAX_SHADOW_PEELS;
// Then the base-colour texture arrays (16 units in all: GL 4.5's minimum for a fragment shader).
constexpr GLenum TEXTURE_UNIT = CAMERA_PREVIOUS_UNIT + 1;
static_assert(TEXTURE_UNIT + MAX_TEXTURE_ARRAYS <= 16, "texture units");
// The shadow volumes' counts in the camera pass: unit 16 (llvmpipe and NVIDIA offer 32; the
// exact pass checks GL_MAX_TEXTURE_IMAGE_UNITS).
constexpr GLenum VOLUME_COUNT_UNIT = 16;
// Storage buffer bindings and image units: glsl_shared.hpp.

// The state every pass relies on: infinite reversed-Z (cube_map.hpp: depth in [0, 1], 1 at
// the near plane, GL_GREATER), no culling (the map holds every surface), no blending.
// And none of the exact camera pass's (gl_camera_exact.cpp): no stencil test, no clip
// distance, no logic op, every colour channel written (a pass it left midway, stopped by a
// time limit, leaves no trace).
inline void set_pass_state() {
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ZERO);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_CLIP_DISTANCE0);
  glDisable(GL_COLOR_LOGIC_OP);
  glDisable(GL_SCISSOR_TEST);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

// The stencil test of a view of level L: draw where the stencil is L, change nothing.
inline void stencil_level(int level) {
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_EQUAL, level, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glStencilMask(0xff);
}

// The camera's sample grid (full_w x full_h, GL window coordinates, y up) cut into tiles of
// at most CAMERA_TILE a side, each rendered with a margin of MARGIN_X columns and MARGIN_Y
// rows around it that is not kept: a triangle far larger than the view (a kilometre of
// ground) is cut by the clipper at the viewport's edges, and the cut lands a fraction of a
// sample off, so the outer samples of a tile without margin miss it. The margins keep the
// pixel grid (8 and 4 samples a pixel).
struct SampleTiles {
  static constexpr int MARGIN_X = 8, MARGIN_Y = 4;
  int64_t full_w = 0, full_h = 0;
  int tile_w = 0, tile_h = 0;  // the kept part
  SampleTiles(int64_t w, int64_t h, int max_size) : full_w(w), full_h(h) {
    const int64_t limit = std::min<int64_t>(CAMERA_TILE, max_size - 2 * MARGIN_X);
    tile_w = static_cast<int>(std::min(full_w, limit));
    tile_h = static_cast<int>(std::min(full_h, limit));
  }
  int target_w() const { return tile_w + 2 * MARGIN_X; }
  int target_h() const { return tile_h + 2 * MARGIN_Y; }
  // The tile at (x0, y0) of the grid, margins included, filling the viewport: the full
  // grid's clip coordinates scaled and shifted (one tile: identity).
  glm::mat4 matrix(int64_t x0, int64_t y0) const;
  // The index in a target-sized readback of sample (gx, gy) of the tile's kept part.
  size_t index(int64_t gx, int64_t gy) const {
    return static_cast<size_t>((gy + MARGIN_Y) * target_w() + gx + MARGIN_X);
  }
};

// The camera's clip matrix with the eye at the origin (scene.vert subtracts the eye).
inline glm::mat4 relative_camera_clip(const Camera& camera, double near_distance) {
  const double aspect = static_cast<double>(camera.width) / camera.height;
  return camera_clip_matrix(glm::dvec3(0.0), camera.look_at - camera.position, camera.up,
                            glm::radians(camera.fov_y_deg), aspect, near_distance);
}

inline glm::mat4 tile_matrix(int64_t full_w, int64_t full_h, int64_t x0, int64_t y0, int tile_w, int tile_h) {
  glm::mat4 tile(1.f);
  tile[0][0] = float(double(full_w) / tile_w);
  tile[3][0] = float(-double(full_w) / tile_w * (double(2 * x0 + tile_w) / double(full_w) - 1.0));
  tile[1][1] = float(double(full_h) / tile_h);
  tile[3][1] = float(-double(full_h) / tile_h * (double(2 * y0 + tile_h) / double(full_h) - 1.0));
  return tile;
}

inline glm::mat4 SampleTiles::matrix(int64_t x0, int64_t y0) const {
  return tile_matrix(full_w, full_h, x0 - MARGIN_X, y0 - MARGIN_Y, target_w(), target_h());
}

// One framebuffer: distance (R32F) + object id (R32UI), or colour (RGBA32F); depth 32F with
// 8 stencil bits (the mirror levels of gl_camera_exact.cpp).
struct GlTarget {
  int width = 0, height = 0;
  bool distance_pass = false;
  GLuint fbo = 0, color0 = 0, color1 = 0, depth = 0;

  GlTarget(int w, int h, bool distance);
  ~GlTarget();
  GlTarget(const GlTarget&) = delete;
  GlTarget& operator=(const GlTarget&) = delete;

  // Binds the target, sets the state every pass relies on, and clears it.
  void clear(const glm::dvec3& background) const;
  // Reads attachment `index` into `out` (`components` values per texel, GL row order).
  void read(int index, GLenum format, GLenum type, void* out) const;
};

// The framebuffer that renders into the cube lookup textures (the shadow maps, the
// environment map): an n x n depth buffer, the colour attached by the pass, face by face.
struct LookupTarget {
  GLuint fbo = 0, depth = 0;
  int n = 0;

  LookupTarget() = default;
  ~LookupTarget();
  LookupTarget(const LookupTarget&) = delete;
  LookupTarget& operator=(const LookupTarget&) = delete;

  // Binds the framebuffer with a new n x n depth buffer.
  void bind(int size);
  // Clears it (a shadow map: +infinity; the environment: `background`).
  void clear(bool distance, const glm::dvec3& background) const;
};

// The view a draw is made through. Level 0 is the camera's own (or a cube face's); level
// L + 1 is what a planar mirror seen at level L shows (gl_camera_exact.cpp). The scene is
// drawn through `model` (the reflections about the mirrors passed, composed: world ->
// virtual world), shaded at its own positions as seen from `eye` (the camera unfolded
// through the mirrors, in world coordinates), keeping what lies on `plane`'s positive side
// (the last mirror's front), without the mirror `skip` (its reflector + 1) it is seen
// through.
struct MirrorView {
  int level = 0;
  glm::dmat4 model{1.0};
  glm::dvec3 eye{0.0};
  glm::dvec4 plane{0.0, 0.0, 0.0, 1.0};  // keeps everything
  uint32_t skip = 0;
  // The tile's pixels the view can reach (x, y, width, height): the bounds of its mirror's
  // projection within its parent's (a scissor: the stencil decides, this saves the work).
  glm::ivec4 scissor{0, 0, 0, 0};

  // The view's transform without its translation: scene.vert draws relative to the eye, so
  // the reflections act on a relative vertex by their linear part alone.
  glm::dmat4 linear() const {
    glm::dmat4 l = model;
    l[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);
    return l;
  }
};

// Throws RuntimeFailure naming `what` when the bound framebuffer is incomplete.
void check_framebuffer(const std::string& what);

}  // namespace abcube
