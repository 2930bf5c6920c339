// The exact camera pass's colour shaded once a pixel and surface (GlShadingGroups;
// ExactCameraOptions::Shading::pixels; docs/design/camera-groups.md): the visible triangle
// at each sample of a view (camera_ids.frag), then one fragment a pixel groups the samples
// and shades each group once (camera_groups.frag).
#pragma once
#include <glad/gl.h>

#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "gl/gl_program.hpp"

namespace abcube {

class GlSceneBuffers;
struct GlTarget;
struct MirrorView;

// What the colour of one view of the exact camera pass reads besides the scene: the
// uniforms its colour programs (camera_exact.frag, camera_groups.frag) share.
struct ViewShading {
  bool volumes = false;              // the view's shadow-volume counts are drawn
  int volume_layers = 0;             // how many
  bool bounces_left = false;         // a mirror seen in it shows its own view
  bool shadows_approximate = false;  // some lit samples' shadows come from the maps
  bool environment = false;          // the environment map stands in for what is not drawn
  // Sets them on `program`, made current.
  void set(const GlProgram& program) const;
};

class GlShadingGroups {
 public:
  // Compiles its programs.
  explicit GlShadingGroups(const GlSceneBuffers& buffers);
  ~GlShadingGroups();
  GlShadingGroups(const GlShadingGroups&) = delete;
  GlShadingGroups& operator=(const GlShadingGroups&) = delete;

  // Why the colour is shaded once a sample instead ("" when it can be once a pixel): a
  // sample's key holds 32 volume counts, and the vertex arrays must fit a storage block.
  static std::string why_not(size_t volume_lights, GLsizei vertex_count);

  // The colour of `view` into `target` (bound, its state set, the lights uploaded, the
  // lookups bound on program()), blending over its texels; `portals`: the reflector ids'
  // buffer (0: none). Leaves the depth and stencil tests on and the target's viewport.
  void shade(GlTarget& target, const glm::mat4& clip, const MirrorView& view, const ViewShading& shading,
             GLuint portals);

  const GlProgram& program() const { return *groups_program_; }
  const GlProgram& ids_program() const { return *ids_program_; }
  // The camera view's pixels shaded whole: colour and weight, one texel a pixel (0 before
  // the first shade()).
  GLuint pixel_color() const;
  GLuint pixel_weight() const;

 private:
  struct Buffers;
  void mark_samples(const glm::mat4& clip, const MirrorView& view, const glm::ivec4& pixels, int volume_layers);

  const GlSceneBuffers& buffers_;
  std::unique_ptr<GlProgram> ids_program_, groups_program_;
  std::unique_ptr<Buffers> buffers_of_target_;
};

}  // namespace abcube
