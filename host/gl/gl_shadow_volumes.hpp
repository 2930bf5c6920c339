// The shadow volumes of the exact camera pass (GlShadowVolumes; course notes 3.3; Everitt &
// Kilgard 2002): built once per volume light (a light's opaque blockers, and its
// translucent ones when the scene has any, each a count of its own), and counted depth-fail
// per view into a layer a count, which the colour pass reads (S_l = 0 where a count is not 0).
#pragma once
#include <glad/gl.h>

#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gl/gl_program.hpp"
#include "gpu_geometry/shadow_volume.hpp"

namespace abcube {

class GlSceneBuffers;
struct GlTarget;
struct MirrorView;

class GlShadowVolumes {
 public:
  explicit GlShadowVolumes(const GlSceneBuffers& buffers);
  ~GlShadowVolumes();
  GlShadowVolumes(const GlShadowVolumes&) = delete;
  GlShadowVolumes& operator=(const GlShadowVolumes&) = delete;

  // Why this GL cannot draw the volumes' near caps ("" when it can): they are read from a
  // storage buffer by the vertex stage (volume_caps.glsl).
  std::string why_not() const;
  // Builds the volumes the first time (later calls keep them: the lights do not change).
  void build();
  // The counts' buffers beside `target` (its size, its depth-stencil), made anew when the
  // target changed.
  void attach(const GlTarget& target);
  // The view's counts: per volume light, in its layer, the depth-fail count of its volume's
  // faces behind or at the view's surfaces (the view's depth drawn in the attached target),
  // over the view's scissor, in its stencil level.
  void count(const glm::mat4& clip, const MirrorView& view);

  // Per count, its light; per light, its opaque and its translucent blockers' count (-1:
  // none). Empty before build().
  const std::vector<int>& lights() const { return lights_; }
  const std::vector<int>& opaque_bit() const { return opaque_bit_; }
  const std::vector<int>& translucent_bit() const { return translucent_bit_; }
  // The counts, a layer of an R32F array per volume light (attach() first).
  GLuint counts() const;
  uint64_t triangle_count() const { return triangles_; }
  double build_ms() const { return build_ms_; }

 private:
  struct Counts;
  // Runs of consecutive casting triangles, as vertex ranges of the scene's buffer.
  struct CapRuns {
    std::vector<GLint> first;
    std::vector<GLsizei> count;
  };
  void add_volume(size_t light, Blockers kind);
  void draw_faces_at_infinity(int layer, const glm::mat4& clip, const MirrorView& view);

  const GlSceneBuffers& buffers_;
  bool built_ = false;
  std::vector<int> lights_, opaque_bit_, translucent_bit_;
  // Each volume light's volume (shadow_volume.hpp): its caps' codes, also in a storage
  // buffer each (caps_, read by scene.vert's VOLUME_CAPS when the scene's own vertex buffer
  // draws the near caps), and its sides; its faces at infinity are clipped per view and tile
  // on the CPU into clipped_ and drawn from clipped_vbo_.
  std::vector<ShadowVolume> volumes_;
  std::vector<GLuint> caps_;
  std::vector<CapRuns> cap_runs_;
  std::vector<ShadowVolumeVertex> clipped_;
  GLuint clipped_vao_ = 0, clipped_vbo_ = 0;
  std::unique_ptr<GlProgram> program_;  // shadow_volume.frag
  std::unique_ptr<Counts> counts_;
  uint64_t triangles_ = 0;
  double build_ms_ = 0;
};

}  // namespace abcube
