// A scene, loaded once and shared by every render of it (docs/scene-format.md).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <abcube/scene_limits.hpp>

namespace abcube {

struct SceneData;  // the loaded scene (cpu_core/scene/scene_data.hpp)
class SceneCache;  // its per-scene search and tracer data (cpu_core/shading/scene_cache.hpp)

// A validated, tessellated scene in world space. Cheap to copy: copies share one loaded
// scene and its per-scene data (the mesh neighbours of the searches, the lens fits, the
// exact tracer's BVH), which are built once, on the first render that needs them, and
// reused by every later render of the scene from any Renderer, whatever its camera.
//
// Thread safety: a Scene is immutable once loaded; any number of threads may render it at
// once (each with its own Renderer).
class Scene {
 public:
  // A model file (.gltf, .glb, .obj) loads as the scene of that model alone, framed and lit
  // (docs/models-and-textures.md "A model file as the scene").
  // Throws InputError with one line naming the place ("FILE:LINE:COL: ..." for JSON
  // syntax, "FILE: objects[3].radius: ..." for values, a file outside limits.root, ...).
  static Scene load(const std::string& path, const SceneLimits& limits = {}, const SceneOverrides& set = {});
  // The same from JSON text in memory: `name` stands for the file in messages and
  // `base_dir` resolves relative mesh paths.
  static Scene from_json(const std::string& json_text, const std::string& name = "<scene>",
                         const std::string& base_dir = ".", const SceneLimits& limits = {},
                         const SceneOverrides& set = {});
  // The same scene loaded again from its source (its file, or its JSON text) with these
  // values replaced; the scene itself when `set` is empty.
  Scene with_overrides(const SceneOverrides& set) const;

  const std::string& name() const;  // the file as given, for messages
  int width() const;                // camera image size in pixels
  int height() const;
  size_t triangle_count() const;
  size_t object_count() const;
  std::string method() const;   // render.method of the file
  int cube_resolution() const;  // render.cube_resolution (N)
  int max_depth() const;        // render.max_depth
  double load_ms() const;       // what loading took (parse, validate, tessellate)
  // What loaded but is likely a mistake, one line each naming the place (a mesh without
  // triangles: "scene.json: objects[2].file: warning: mesh \"empty.obj\" has no triangles").
  // The CLI prints them on stderr; nothing else does.
  const std::vector<std::string>& warnings() const;

  // The loaded data and its per-scene cache, for code built on the internal headers.
  const SceneData& data() const;
  const SceneCache& cache() const;

 private:
  struct State;
  explicit Scene(std::shared_ptr<const State> state) : state_(std::move(state)) {}
  std::shared_ptr<const State> state_;
};

}  // namespace abcube
