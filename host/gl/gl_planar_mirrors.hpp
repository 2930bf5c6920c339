// The planar mirrors of the exact camera pass (GlPlanarMirrors; course notes 4.1.2; Kilgard
// 1999): the scene's planar reflectors (planar_reflectors.hpp) as the GL draws them, a
// reflector id per vertex and each reflector's triangles as a range of an index buffer, and
// the view that each one shows: the scene reflected about its plane, clipped at it.
#pragma once
#include <glad/gl.h>

#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "gl/gl_program.hpp"
#include "gpu_geometry/planar_reflectors.hpp"

namespace abcube {

class GlSceneBuffers;
struct MirrorView;

class GlPlanarMirrors {
 public:
  // Finds the scene's planar reflectors and adds their ids to the scene's vertex array.
  explicit GlPlanarMirrors(const GlSceneBuffers& buffers);
  ~GlPlanarMirrors();
  GlPlanarMirrors(const GlPlanarMirrors&) = delete;
  GlPlanarMirrors& operator=(const GlPlanarMirrors&) = delete;

  const PlanarReflectors& reflectors() const { return reflectors_; }
  // Each vertex's reflector + 1 (0: none), a buffer the per-pixel shading reads; 0 when the
  // scene has no planar reflector.
  GLuint portal_ids() const { return portal_vbo_; }

  // Reflector `r`'s triangles drawn through `view`.
  void draw(const GlProgram& program, const glm::mat4& clip, const MirrorView& view, size_t r) const;
  // The pixels of a width x height tile that reflector `r` covers in `view` (within its
  // scissor); empty (zero size) when it falls outside.
  glm::ivec4 bounds(size_t r, const glm::mat4& clip, const MirrorView& view, int width, int height) const;
  // The view that reflector `r`, seen from `view`'s eye on its `side` (the sign of
  // PlanarReflector::side), shows over the pixels `scissor`.
  MirrorView behind(size_t r, const MirrorView& view, double side, const glm::ivec4& scissor) const;

 private:
  const GlSceneBuffers& buffers_;
  PlanarReflectors reflectors_;
  GLuint portal_vbo_ = 0, portal_ebo_ = 0;
  std::vector<std::pair<size_t, size_t>> ranges_;  // per reflector: first index, count
};

}  // namespace abcube
