// abcube::Scene: one loaded scene and its per-scene cache, shared by its copies.
#include <abcube/scene.hpp>

#include "base/error.hpp"
#include "base/timer.hpp"
#include "render/method.hpp"
#include "scene/scene_load.hpp"
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

// What an abcube::Scene shares between its copies: the loaded scene and its cache.
struct Scene::State {
  State(SceneData d, double ms, SceneSource s) : data(std::move(d)), cache(data), load_ms(ms), source(std::move(s)) {}
  State(const State&) = delete;
  State& operator=(const State&) = delete;

  const SceneData data;
  const SceneCache cache;  // refers to `data`: State never moves (held by shared_ptr)
  const double load_ms;    // parsing, validating and tessellating the file
  const SceneSource source;
};

namespace {

LoadLimits load_limits(const SceneLimits& limits) {
  if (limits.max_memory_mib > (uint64_t{1} << 30)) throw InputError("max-memory: must be at most 2^30 MiB");
  if (limits.threads < 0) throw InputError("threads: must be >= 0, got " + std::to_string(limits.threads));
  LoadLimits l;
  static_cast<SceneLimits&>(l) = limits;
  for (const RenderMethod* m : registered_methods()) l.methods.push_back(m->name());  // render.method
  return l;
}

}  // namespace

namespace {

SceneData load_source(const SceneSource& s) {
  if (!s.path.empty()) return load_scene(s.path, load_limits(s.limits), s.set);
  return load_scene_text(s.text, s.name, s.base_dir, load_limits(s.limits), s.set);
}

}  // namespace

Scene Scene::load(const std::string& path, const SceneLimits& limits, const SceneOverrides& set) {
  const Clock::time_point t0 = Clock::now();
  SceneSource source{path, "", "", "", limits, set};
  SceneData data = load_source(source);
  return Scene(std::make_shared<const State>(std::move(data), ms_since(t0), std::move(source)));
}

Scene Scene::from_json(const std::string& json_text, const std::string& name, const std::string& base_dir,
                       const SceneLimits& limits, const SceneOverrides& set) {
  const Clock::time_point t0 = Clock::now();
  SceneSource source{"", json_text, name, base_dir, limits, set};
  SceneData data = load_source(source);
  return Scene(std::make_shared<const State>(std::move(data), ms_since(t0), std::move(source)));
}

Scene Scene::with_overrides(const SceneOverrides& set) const {
  if (set.empty()) return *this;
  const Clock::time_point t0 = Clock::now();
  SceneSource source = state_->source;
  source.set.insert(source.set.end(), set.begin(), set.end());
  SceneData data = load_source(source);
  return Scene(std::make_shared<const State>(std::move(data), ms_since(t0), std::move(source)));
}

const std::string& Scene::name() const { return state_->data.file; }
int Scene::width() const { return state_->data.camera.width; }
int Scene::height() const { return state_->data.camera.height; }
size_t Scene::triangle_count() const { return state_->data.triangles->triangle_count(); }
size_t Scene::object_count() const { return state_->data.objects.size(); }
std::string Scene::method() const { return state_->data.render.method; }
int Scene::cube_resolution() const { return state_->data.render.cube_resolution; }
int Scene::max_depth() const { return state_->data.render.max_depth; }
double Scene::load_ms() const { return state_->load_ms; }
const std::vector<std::string>& Scene::warnings() const { return state_->data.warnings; }
const SceneData& Scene::data() const { return state_->data; }
const SceneCache& Scene::cache() const { return state_->cache; }

}  // namespace abcube
