// The cube shadow maps of the gpu method (GlShadowMaps): per shadow-casting light, the
// distance to the nearest opaque caster on the six faces around it, and the translucent
// casters in front of it peeled into up to MAX_SHADOW_PEELS layers whose transmittances
// multiply (the CPU's rule "shadows", shading.hpp). Camera and cube passes look them up.
#pragma once
#include <glad/gl.h>

#include <memory>
#include <vector>

#include "gl/gl_types.hpp"
#include "gl/gl_program.hpp"

namespace abcube {

class GlSceneBuffers;
struct LookupTarget;

class GlShadowMaps {
 public:
  explicit GlShadowMaps(const GlSceneBuffers& buffers);
  ~GlShadowMaps();
  GlShadowMaps(const GlShadowMaps&) = delete;
  GlShadowMaps& operator=(const GlShadowMaps&) = delete;

  // One map per light with cast_shadows, n x n a face, rendered through `lookup`. Returns
  // how many lights. Maps of the same size built before are kept (the lights do not change).
  int build(int n, LookupTarget& lookup, GpuTimings& timings);
  // The maps and their peels on their units (gl_targets.hpp), and their uniforms on
  // `program`, made current; without maps, u_shadows false.
  void bind(const GlProgram& program) const;

  // Per light, its layer of the maps (-1: it casts no shadows).
  const std::vector<int>& layers() const { return layer_; }
  int peels() const { return static_cast<int>(peels_.size()); }
  bool peels_capped() const { return peels_capped_; }

 private:
  void draw_casters(GLuint maps, const LookupTarget& lookup) const;
  void peel_translucent_casters(int n, int layers, const LookupTarget& lookup);

  const GlSceneBuffers& buffers_;
  std::unique_ptr<GlProgram> program_;  // shadow_caster.frag
  GLuint maps_ = 0;                     // a cube-map array, a layer per light and face
  std::vector<GLuint> peels_;           // one cube-map array per peel
  bool peels_capped_ = false;
  int n_ = 0;               // the size the maps were built at; 0 while none are whole
  std::vector<int> layer_;  // per light, -1 when it casts no shadows
};

}  // namespace abcube
