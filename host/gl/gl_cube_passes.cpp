// The passes over the six cube faces around a centre: the distance prepass (distances and
// object ids) and the Z-buffer colour.
#include <vector>

#include "base/parallel.hpp"
#include "base/timer.hpp"
#include "gl/gl_passes.hpp"
#include "gl/gl_scene_parts.hpp"
#include "raster/cube_map.hpp"

namespace abcube {

void GlScene::cube_distance(const glm::dvec3& center, int n, CubeImage* distance, CubeIds* ids, int n_t) {
  GlSceneParts& p = *parts_;
  const int h = n_t > 0 ? n_t : n;
  GlTarget& t = p.target(n, h, true);
  *distance = CubeImage(n, 1);
  if (ids) ids->n = n;
  for (int face = 0; face < CUBE_FACES; ++face) {
    check_deadline();
    Clock::time_point t0 = Clock::now();
    t.clear(p.scene.background);
    p.buffers.draw(*p.distance_program, face_clip_matrix(face, glm::dvec3(0.0), p.buffers.near_distance()), center);
    glFinish();
    p.timings.cube_distance_ms += ms_since(t0);
    t0 = Clock::now();
    Image& img = distance->faces[static_cast<size_t>(face)];
    img = Image(n, h, 1);
    t.read(0, GL_RED, GL_FLOAT, img.data.data());
    if (ids) {
      auto& f = ids->faces[static_cast<size_t>(face)];
      f.assign(static_cast<size_t>(n) * h, NO_OBJECT);
      t.read(1, GL_RED_INTEGER, GL_UNSIGNED_INT, f.data());
    }
    p.timings.readback_ms += ms_since(t0);
  }
  check_gl("cube distance prepass");
}

CubeImage GlScene::cube_color(const glm::dvec3& center, int n) {
  GlSceneParts& p = *parts_;
  GlTarget& t = p.target(n, n, false);
  CubeImage out(n, 3);
  p.upload_lights(center);
  p.bind_lookups(*p.phong_program, false);
  std::vector<float> rgba(static_cast<size_t>(n) * n * 4);
  for (int face = 0; face < CUBE_FACES; ++face) {
    check_deadline();
    Clock::time_point t0 = Clock::now();
    t.clear(p.scene.background);
    p.buffers.draw(*p.phong_program, face_clip_matrix(face, glm::dvec3(0.0), p.buffers.near_distance()), center);
    glFinish();
    p.timings.cube_color_ms += ms_since(t0);
    t0 = Clock::now();
    t.read(0, GL_RGBA, GL_FLOAT, rgba.data());
    Image& img = out.faces[static_cast<size_t>(face)];
    for (size_t k = 0; k < static_cast<size_t>(n) * n; ++k) {
      for (int c = 0; c < 3; ++c) img.data[k * 3 + c] = rgba[k * 4 + c];
    }
    p.timings.readback_ms += ms_since(t0);
  }
  check_gl("cube colour pass");
  return out;
}

}  // namespace abcube
