// What a scene needs: the cube resolution from an error target, and which passes and
// searches can be skipped.
#pragma once
#include <string>
#include <vector>

#include "scene/scene_data.hpp"

namespace abcube {

// Thesis 9.3.4: with an N x N face the Error_Parallax of a found point is about 1/(2 N^2)
// (N = 100 -> 5e-5, 200 -> 1.25e-5, 300 -> 5.6e-6). The smallest N whose bound meets
// `target`: ceil(1 / sqrt(2 target)).
int resolution_for_error(double target);
double parallax_bound(int n);  // 1 / (2 N^2)

struct PlanStep {
  std::string pass;
  bool run = true;
  std::string why;  // why it runs or why it was skipped
};

// The plan of a cube-map render (methods abuffer, zbuffer, envmap). `everything` forces
// every step (for measuring what the skips save); the image does not change.
struct RenderPlan {
  bool cube_map = true;            // any reflect/transmit material or shadowing light
  std::vector<bool> shadow_walks;  // per light: it casts shadows
  bool reflection_searches = true, refraction_searches = true;
  std::vector<PlanStep> steps;
};
RenderPlan make_plan(const SceneData& scene, bool everything);

}  // namespace abcube
