// The planar mirrors of the exact camera pass (GlPlanarMirrors): their buffers, their pixels
// in a view, and the view each one shows.
#include "gl/gl_planar_mirrors.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "gl/gl_targets.hpp"
#include "gl/gl_scene_buffers.hpp"

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

}  // namespace

GlPlanarMirrors::GlPlanarMirrors(const GlSceneBuffers& buffers)
    : buffers_(buffers), reflectors_(find_planar_reflectors(buffers.scene())) {
  if (reflectors_.reflectors.empty()) return;
  // A reflector id per vertex, and each one's triangles as a range of an index buffer, both
  // kept with the scene's vertex array.
  std::vector<uint32_t> ids(buffers.scene().triangles->positions.size()), indices;
  for (size_t v = 0; v < ids.size(); ++v) ids[v] = reflectors_.reflector_of_triangle[v / 3];
  buffers.bind_vertex_array();
  glGenBuffers(1, &portal_vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, portal_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(ids.size() * sizeof(uint32_t)), ids.data(), GL_STATIC_DRAW);
  glVertexAttribIPointer(5, 1, GL_UNSIGNED_INT, sizeof(uint32_t), nullptr);
  glEnableVertexAttribArray(5);
  for (const PlanarReflector& r : reflectors_.reflectors) {
    ranges_.emplace_back(indices.size(), 3 * r.triangles.size());
    for (const uint32_t tri : r.triangles) {
      for (uint32_t k = 0; k < 3; ++k) indices.push_back(3 * tri + k);
    }
  }
  glGenBuffers(1, &portal_ebo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, portal_ebo_);  // kept by the vertex array
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(),
               GL_STATIC_DRAW);
}

GlPlanarMirrors::~GlPlanarMirrors() {
  const GLuint buffers[] = {portal_vbo_, portal_ebo_};
  glDeleteBuffers(2, buffers);
}

void GlPlanarMirrors::draw(const GlProgram& program, const glm::mat4& clip, const MirrorView& view, size_t r) const {
  buffers_.set_view(program, clip, view);
  buffers_.bind_vertex_array();
  const auto [first, count] = ranges_[r];
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                 reinterpret_cast<const void*>(first * sizeof(uint32_t)));
}

// The bounds of the reflector's corners drawn through clip * the view's transform relative
// to its eye (scene.vert), within the view's scissor; the scissor itself when a corner is
// behind the eye.
glm::ivec4 GlPlanarMirrors::bounds(size_t r, const glm::mat4& clip, const MirrorView& view, int width,
                                   int height) const {
  const TriangleSoup& soup = *buffers_.scene().triangles;
  const glm::dmat4 clip_model = glm::dmat4(clip) * view.linear();
  const glm::ivec4& parent = view.scissor;
  double lo_x = 1e300, lo_y = 1e300, hi_x = -1e300, hi_y = -1e300;
  for (const uint32_t t : reflectors_.reflectors[r].triangles) {
    for (size_t k = 0; k < 3; ++k) {
      const glm::dvec4 c =
          clip_model * glm::dvec4(glm::dvec3(soup.positions[3 * static_cast<size_t>(t) + k]) - view.eye, 1.0);
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

MirrorView GlPlanarMirrors::behind(size_t r, const MirrorView& view, double side, const glm::ivec4& scissor) const {
  const PlanarReflector& mirror = reflectors_.reflectors[r];
  const glm::dmat4 reflect = reflection_matrix(mirror.normal, mirror.offset);
  MirrorView out;
  out.level = view.level + 1;
  out.model = view.model * reflect;
  out.eye = glm::dvec3(reflect * glm::dvec4(view.eye, 1.0));
  out.plane = (side > 0 ? 1.0 : -1.0) * glm::dvec4(mirror.normal, mirror.offset);
  out.skip = static_cast<uint32_t>(r + 1);
  out.scissor = scissor;
  return out;
}

}  // namespace abcube
