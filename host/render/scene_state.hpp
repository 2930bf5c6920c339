// What an abcube::Scene shares between its copies: the loaded scene and its cache.
#pragma once
#include <abcube/scene.hpp>

#include "scene/scene_data.hpp"
#include "shading/scene_cache.hpp"

namespace abcube {

struct Scene::State {
  State(SceneData d, double ms) : data(std::move(d)), cache(data), load_ms(ms) {}
  State(const State&) = delete;
  State& operator=(const State&) = delete;

  const SceneData data;
  const SceneCache cache;  // refers to `data`: State never moves (held by shared_ptr)
  const double load_ms;    // parsing, validating and tessellating the file
};

}  // namespace abcube
