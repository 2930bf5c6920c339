// The camera view by the Z-buffer: the object id at each sample, and the Phong colour at
// the pixel centres or the 4x8 samples, peeled front to back under coverage transparency.
// (The exact camera pass is gl_camera_exact.cpp's.)
#include <algorithm>
#include <vector>

#include "base/parallel.hpp"
#include "base/samples.hpp"
#include "base/timer.hpp"
#include "gl/gl_camera_exact.hpp"
#include "gl/gl_passes.hpp"
#include "gl/gl_scene_parts.hpp"

namespace abcube {

std::vector<uint32_t> GlScene::camera_objects(const Camera& camera) {
  GlSceneParts& p = *parts_;
  const int64_t full_w = int64_t{camera.width} * MASK_COLUMNS, full_h = int64_t{camera.height} * MASK_ROWS;
  const SampleTiles tiles(full_w, full_h, p.buffers.max_size());
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  GlTarget& t = p.target(tiles.target_w(), tiles.target_h(), true);
  const glm::mat4 clip = relative_camera_clip(camera, p.buffers.near_distance());
  std::vector<uint32_t> out(static_cast<size_t>(full_w * full_h), NO_OBJECT),
      tile_ids(size_t(tiles.target_w()) * size_t(tiles.target_h()));
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      t.clear(p.scene.background);
      p.buffers.draw(*p.distance_program, tiles.matrix(x0, y0) * clip, camera.position);
      t.read(1, GL_RED_INTEGER, GL_UNSIGNED_INT, tile_ids.data());
      // GL's row 0 is the bottom; the grid's row 0 is the top.
      for (int64_t gy = 0; gy < tile_h && y0 + gy < full_h; ++gy) {
        for (int64_t gx = 0; gx < tile_w && x0 + gx < full_w; ++gx) {
          out[static_cast<size_t>((full_h - 1 - (y0 + gy)) * full_w + x0 + gx)] = tile_ids[tiles.index(gx, gy)];
        }
      }
    }
  }
  check_gl("camera object ids");
  return out;
}

namespace {

// The Z-buffer colour of one tile of the camera's samples. With coverage transparency
// (rule "opacity") the view is peeled front to back, each layer blended under the ones
// before it, C += T op c, T *= 1 - op, the background last; without, one layer.
class CameraTile {
 public:
  CameraTile(GlSceneParts& parts, const SampleTiles& tiles, bool transparent)
      : parts_(parts),
        tiles_(tiles),
        transparent_(transparent),
        samples_(static_cast<size_t>(tiles.target_w()) * static_cast<size_t>(tiles.target_h())),
        rgba_(samples_ * 4),
        colour_(samples_ * 3),
        through_(samples_) {
    if (!transparent_) return;
    glGenTextures(1, &previous_);
    glBindTexture(GL_TEXTURE_2D, previous_);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG32F, tiles.target_w(), tiles.target_h());
    glGenQueries(1, &query_);
    const GlProgram& phong = *parts_.phong_program;
    phong.use();
    glUniform1i(phong.uniform("u_previous"), static_cast<GLint>(CAMERA_PREVIOUS_UNIT));
  }
  ~CameraTile() {
    if (!transparent_) return;
    parts_.phong_program->use();
    glUniform1i(parts_.phong_program->uniform("u_peel"), 0);
    glDeleteTextures(1, &previous_);
    glDeleteQueries(1, &query_);
  }
  CameraTile(const CameraTile&) = delete;
  CameraTile& operator=(const CameraTile&) = delete;

  // Draws the tile through `clip` from `eye`; returns the layers that drew something.
  int draw(const glm::mat4& clip, const glm::dvec3& eye) {
    std::fill(colour_.begin(), colour_.end(), 0.0);
    std::fill(through_.begin(), through_.end(), 1.0);
    int layers = 0;
    for (int layer = 0; layer < (transparent_ ? MAX_CAMERA_LAYERS : 1); ++layer) {
      if (!draw_layer(layer, clip, eye)) break;
      layers = layer + 1;
      const Clock::time_point t0 = Clock::now();
      parts_.current_target().read(0, GL_RGBA, GL_FLOAT, rgba_.data());
      for (size_t k = 0; k < samples_; ++k) {
        const double a = transparent_ ? rgba_[4 * k + 3] : 1.0;
        for (size_t c = 0; c < 3; ++c) colour_[3 * k + c] += through_[k] * a * rgba_[4 * k + c];
        through_[k] *= 1.0 - a;
      }
      parts_.timings.readback_ms += ms_since(t0);
    }
    return layers;
  }
  // Sample k of the last tile drawn, over the background `bg`.
  double value(size_t k, int c, const glm::dvec3& bg) const {
    return colour_[3 * k + static_cast<size_t>(c)] + through_[k] * bg[c];
  }

 private:
  // Draws peel `layer` (the surfaces behind the previous layer's); whether any sample drew.
  bool draw_layer(int layer, const glm::mat4& clip, const glm::dvec3& eye) {
    const Clock::time_point t0 = Clock::now();
    GlTarget& t = parts_.current_target();
    const GlProgram& phong = *parts_.phong_program;
    phong.use();
    glUniform1i(phong.uniform("u_peel"), layer);
    if (layer > 0) {
      glCopyImageSubData(t.color1, GL_TEXTURE_2D, 0, 0, 0, 0, previous_, GL_TEXTURE_2D, 0, 0, 0, 0, tiles_.target_w(),
                         tiles_.target_h(), 1);
      glActiveTexture(GL_TEXTURE0 + CAMERA_PREVIOUS_UNIT);
      glBindTexture(GL_TEXTURE_2D, previous_);
      glActiveTexture(GL_TEXTURE0);
    }
    t.clear(parts_.scene.background);
    if (transparent_) {
      const float none[4] = {0, 0, 0, 0};  // alpha 0: no surface at this sample
      glClearBufferfv(GL_COLOR, 0, none);
      glBeginQuery(GL_ANY_SAMPLES_PASSED, query_);
    }
    parts_.buffers.draw(phong, clip, eye);
    GLuint drew = 1;
    if (transparent_) {
      glEndQuery(GL_ANY_SAMPLES_PASSED);
      glGetQueryObjectuiv(query_, GL_QUERY_RESULT, &drew);
    }
    glFinish();
    parts_.timings.camera_ms += ms_since(t0);
    return drew != 0;
  }

  GlSceneParts& parts_;
  const SampleTiles& tiles_;
  const bool transparent_;
  const size_t samples_;
  std::vector<float> rgba_;
  std::vector<double> colour_, through_;
  GLuint previous_ = 0, query_ = 0;  // the previous layer's depths; whether a layer drew
};

}  // namespace

Image GlScene::camera_color(const Camera& camera, CameraSamples samples) {
  const bool mask = samples == CameraSamples::mask_4x8;
  if (mask && exact_->plan()) {
    camera_layers_ = 1;
    camera_layers_capped_ = false;
    return exact_->render(camera);
  }
  GlSceneParts& p = *parts_;
  const int64_t sx = mask ? MASK_COLUMNS : 1, sy = mask ? MASK_ROWS : 1;
  const int64_t full_w = camera.width * sx, full_h = camera.height * sy;
  const SampleTiles tiles(full_w, full_h, p.buffers.max_size());
  const int tile_w = tiles.tile_w, tile_h = tiles.tile_h;
  p.target(tiles.target_w(), tiles.target_h(), false);
  p.upload_lights(camera.position);
  p.bind_lookups(*p.phong_program, true);
  const glm::mat4 clip = relative_camera_clip(camera, p.buffers.near_distance());
  bool transparent = false;
  for (const uint32_t id : p.scene.triangles->material_id)
    transparent = transparent || p.scene.materials[id].opacity < 1.0;
  CameraTile tile(p, tiles, transparent);
  std::vector<double> sum(static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height) * 3, 0.0);
  camera_layers_ = 0;
  camera_layers_capped_ = false;
  // Tile (x0, y0) in GL window coordinates of the full sample grid (y up).
  for (int64_t y0 = 0; y0 < full_h; y0 += tile_h) {
    for (int64_t x0 = 0; x0 < full_w; x0 += tile_w) {
      check_deadline();
      const int layers = tile.draw(tiles.matrix(x0, y0) * clip, camera.position);
      camera_layers_ = std::max(camera_layers_, layers);
      camera_layers_capped_ = camera_layers_capped_ || (transparent && layers == MAX_CAMERA_LAYERS);
      // GL's row 0 is the bottom; the image's row 0 is the top.
      for (int64_t gy = 0; gy < tile_h && y0 + gy < full_h; ++gy) {
        const size_t row = static_cast<size_t>((full_h - 1 - (y0 + gy)) / sy);
        for (int64_t gx = 0; gx < tile_w && x0 + gx < full_w; ++gx) {
          double* dst = &sum[(row * static_cast<size_t>(camera.width) + static_cast<size_t>((x0 + gx) / sx)) * 3];
          for (int c = 0; c < 3; ++c) dst[c] += tile.value(tiles.index(gx, gy), c, p.scene.background);
        }
      }
    }
  }
  Image out(camera.width, camera.height, 3);
  const double samples_per_pixel = double(sx * sy);
  for (size_t k = 0; k < sum.size(); ++k) out.data[k] = static_cast<float>(sum[k] / samples_per_pixel);
  check_gl("camera pass");
  return out;
}

}  // namespace abcube
