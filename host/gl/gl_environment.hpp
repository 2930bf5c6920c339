// The environment map of the gpu method (GlEnvironment; Blinn & Newell 1976): the Z-buffer
// colour of the six faces around a centre, kept on the GPU as a cube texture, which later
// camera passes look up for kr and kt.
#pragma once
#include <glad/gl.h>

#include <functional>

#include "gl/gl_types.hpp"
#include "shading/map_shading.hpp"
#include "gl/gl_program.hpp"

namespace abcube {

struct LookupTarget;

class GlEnvironment {
 public:
  GlEnvironment() = default;
  ~GlEnvironment() { drop(); }
  GlEnvironment(const GlEnvironment&) = delete;
  GlEnvironment& operator=(const GlEnvironment&) = delete;

  // A new n x n map: each face cleared to `background` in `lookup`, then drawn by
  // `draw_face(face)` (the colour program and its lookups bound, no environment in it).
  void build(int n, LookupTarget& lookup, const glm::dvec3& background, const std::function<void(int)>& draw_face);
  // Later camera passes look up no environment (max_depth 0, or nothing reflects).
  void drop();
  bool built() const { return texture_ != 0; }

  // How camera passes look the map up: the envmap method's lookup direction (R, bisector,
  // position) and Schlick's weights for kr and kt (shading.hpp).
  void set_lookup(EnvmapLookup lookup, bool fresnel) {
    lookup_ = lookup;
    fresnel_ = fresnel;
  }
  // The lookup's uniforms on `program` (current), u_environment false unless `use` and built.
  void set_uniforms(const GlProgram& program, bool use) const;
  // The map on unit 2 when `use` and built (else none); leaves unit 0 active.
  void bind_texture(bool use) const;

 private:
  GLuint texture_ = 0;
  EnvmapLookup lookup_ = EnvmapLookup::reflected;
  bool fresnel_ = false;
};

}  // namespace abcube
