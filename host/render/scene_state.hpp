// What an abcube::Scene shares between its copies: the loaded scene and its cache.
#pragma once
#include <string>

#include <abcube/scene.hpp>

#include "scene/scene_data.hpp"
#include "shading/scene_cache.hpp"

namespace abcube {

// Where a scene came from, so that it can be loaded again with values replaced
// (Scene::with_overrides): a file, or JSON text with its name and folder.
struct SceneSource {
  std::string path;  // the file; empty for text
  std::string text, name, base_dir;
  SceneLimits limits;
  SceneOverrides set;  // the overrides it was loaded with
};

struct Scene::State {
  State(SceneData d, double ms, SceneSource s) : data(std::move(d)), cache(data), load_ms(ms), source(std::move(s)) {}
  State(const State&) = delete;
  State& operator=(const State&) = delete;

  const SceneData data;
  const SceneCache cache;  // refers to `data`: State never moves (held by shared_ptr)
  const double load_ms;    // parsing, validating and tessellating the file
  const SceneSource source;
};

}  // namespace abcube
