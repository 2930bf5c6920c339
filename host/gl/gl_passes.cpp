// GlScene, the front of the GL passes: the upload, and each pass handed to its technique.
#include "gl/gl_passes.hpp"

#include <memory>
#include <string>
#include <vector>

#include "base/error.hpp"
#include "base/timer.hpp"
#include "gl/gl_abuffer.hpp"
#include "gl/gl_camera_exact.hpp"
#include "gl/gl_resolve_plan.hpp"
#include "gl/gl_scene_parts.hpp"
#include "raster/cube_map.hpp"

namespace abcube {

GlScene::GlScene(const SceneData& scene, const GlSceneOptions& options) {
  const Clock::time_point t0 = Clock::now();
  parts_ = std::make_unique<GlSceneParts>(scene, options);
  exact_ = std::make_unique<GlExactCamera>(*parts_);
  glFinish();
  check_gl("scene upload");
  parts_->timings.upload_ms = ms_since(t0);
}

GlScene::~GlScene() = default;

int GlScene::build_shadow_maps(int n) { return parts_->shadows.build(n, parts_->lookup, parts_->timings); }
int GlScene::shadow_peels() const { return parts_->shadows.peels(); }
bool GlScene::shadow_peels_capped() const { return parts_->shadows.peels_capped(); }

void GlScene::build_environment(const glm::dvec3& center, int n) {
  const Clock::time_point t0 = Clock::now();
  GlSceneParts& p = *parts_;
  if (n > p.buffers.max_size()) {
    throw RuntimeFailure("environment map " + std::to_string(n) + " exceeds GL_MAX_TEXTURE_SIZE");
  }
  p.environment.drop();
  p.upload_lights(center);
  p.bind_lookups(*p.phong_program, false);  // no environment inside the environment
  p.environment.build(n, p.lookup, p.scene.background, [&](int face) {
    p.buffers.draw(*p.phong_program, face_clip_matrix(face, glm::dvec3(0.0), p.buffers.near_distance()), center);
  });
  p.timings.environment_ms += ms_since(t0);
}

void GlScene::drop_environment() { parts_->environment.drop(); }
void GlScene::set_environment_lookup(EnvmapLookup lookup, bool fresnel) {
  parts_->environment.set_lookup(lookup, fresnel);
}

void GlScene::set_exact_camera(const ExactCameraOptions& options) { exact_->set_options(options); }
const ExactCameraStats& GlScene::exact_camera_stats() const { return exact_->stats(); }
bool GlScene::exact_camera_possible() { return exact_->plan(); }
const PlanarReflectors& GlScene::planar_reflectors() const { return exact_->reflectors(); }
const std::vector<uint8_t>& GlScene::exact_pixels() const { return exact_->pixels(); }

void GlScene::set_texture_level0(bool on) { parts_->texture_level0 = on; }
const GpuTimings& GlScene::timings() const { return parts_->timings; }

const GlABufferBuilder& GlScene::abuffer_builder() {
  if (!abuffer_) abuffer_ = std::make_unique<GlABufferBuilder>();
  return *abuffer_;
}
const GlResolvePlanner& GlScene::resolve_planner() {
  if (!resolve_planner_) resolve_planner_ = std::make_unique<GlResolvePlanner>();
  return *resolve_planner_;
}
bool GlScene::soup_pinned() const { return parts_->buffers.pinned(); }
bool GlScene::triangle_ids() const { return parts_->buffers.triangle_ids(); }
double GlScene::near_distance() const { return parts_->buffers.near_distance(); }
int GlScene::max_size() const { return parts_->buffers.max_size(); }

}  // namespace abcube
