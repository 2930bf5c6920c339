#include "scene/plan.hpp"

#include <cmath>

namespace abcube {

int resolution_for_error(double target) { return static_cast<int>(std::ceil(1.0 / std::sqrt(2.0 * target) - 1e-9)); }

double parallax_bound(int n) { return 1.0 / (2.0 * static_cast<double>(n) * static_cast<double>(n)); }

RenderPlan make_plan(const SceneData& scene, bool everything) {
  RenderPlan p;
  bool reflect = false, transmit = false;
  for (const Material& m : scene.materials) {
    reflect = reflect || m.reflect > 0 || (scene.render.fresnel && m.transmit > 0);
    transmit = transmit || m.transmit > 0;
  }
  bool shadows = false;
  for (const PointLight& l : scene.lights) {
    p.shadow_walks.push_back(l.cast_shadows || everything);
    shadows = shadows || l.cast_shadows;
  }
  p.reflection_searches = reflect;
  p.refraction_searches = transmit;
  p.cube_map = everything || reflect || transmit || shadows;
  auto step = [&p](const std::string& pass, bool run, const std::string& why) { p.steps.push_back({pass, run, why}); };
  step("cube_abuffer", p.cube_map,
       p.cube_map
           ? (everything && !(reflect || transmit || shadows) ? "forced (--plan everything)" : "searches need the map")
           : "no reflecting or refracting material and no shadow-casting light");
  step("reflection_searches", reflect, reflect ? "a material reflects" : "no material reflects");
  step("refraction_searches", transmit, transmit ? "a material transmits" : "no material transmits");
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const bool casts = scene.lights[i].cast_shadows;
    step("shadow_walks light " + std::to_string(i), p.shadow_walks[i],
         casts ? "the light casts shadows"
               : (everything ? "forced (--plan everything); result unused" : "the light casts no shadows"));
  }
  step("camera_abuffer", true, "the camera view is always resolved through the A-buffer");
  return p;
}

}  // namespace abcube
