// Loading a scene file (docs/scene-format.md, version 1) into a SceneData.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <abcube/scene_limits.hpp>

#include "scene/scene_data.hpp"

namespace abcube {

// What a scene may ask of the machine that loads it (a server loading scenes it did not
// write): where its files may be, and how many triangles it may hold.
// The public limits (SceneLimits: the root folder, the triangle cap, the memory budget in
// MiB, the threads; each refused with an InputError naming the field or the count before
// anything is made for it) and what only the loader's callers set.
struct LoadLimits : SceneLimits {
  // Input files larger than these are refused before they are read (docs/scene-format.md
  // "Limits"): a scene file (and an MTL file) is text of kilobytes, a mesh can be
  // gigabytes (a 1M-triangle OBJ is about 100 MB). A mesh file larger than the memory
  // available is refused too: its triangles take more room than its text.
  uint64_t max_scene_bytes = MAX_SCENE_BYTES;
  uint64_t max_mesh_bytes = MAX_MESH_BYTES;
  // The names render.method may take: the host's registered methods. Empty: any name.
  std::vector<std::string> methods;
  static constexpr uint64_t MAX_SCENE_BYTES = uint64_t{64} << 20;  // 64 MiB
  static constexpr uint64_t MAX_MESH_BYTES = uint64_t{8} << 30;    // 8 GiB

  uint64_t max_memory_bytes() const { return max_memory_mib << 20; }
};

// SceneOverride and SceneOverrides: <abcube/scene_limits.hpp>.

// Parses, validates, tessellates and transforms. Throws InputError with one line that
// names the place: "FILE:LINE:COL: ..." for JSON syntax, "FILE: objects[3].radius: ..."
// for values. Unknown fields, NaN/inf, degenerate cameras, missing mesh files, unknown
// materials and out-of-range weights are errors; zero-area triangles are dropped and
// counted in SceneData::dropped_triangles.
SceneData load_scene(const std::string& path);
SceneData load_scene(const std::string& path, const LoadLimits& limits, const SceneOverrides& set = {});

// Same, from text already in memory; `name` stands for the file in messages and
// `base_dir` resolves relative mesh paths.
SceneData load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir);
SceneData load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir,
                          const LoadLimits& limits, const SceneOverrides& set = {});

// Peak resident bytes a triangle of scene data costs above the process's own, whatever the
// method (the soup, the mesh neighbours, the tracer's tree and its build): the largest
// bench/memory.py finds on large meshes, rounded up, so that the estimate does not fall
// short (docs/performance.md has the measurements).
constexpr uint64_t SCENE_TRIANGLE_BYTES = 170;

// The memory a render may use: `max_memory_bytes` when it is set (--max-memory), else the
// memory available (available_memory_bytes: MemAvailable, or less under a cgroup limit).
uint64_t memory_budget_bytes(uint64_t max_memory_bytes);

// "above --max-memory M MiB" or "above the M MiB of memory available", for messages.
std::string budget_words(uint64_t budget_bytes, bool capped);

// Bytes a render of this scene needs at its camera size and cube resolution (images and
// their per-pixel indices, cube faces, triangles and, for a method that draws with GL
// (`gl`), the GL copies, shadow volumes and shadow maps) beside its A-buffers' fragments,
// which are counted when they are built (the A-buffer gets what is left of the budget).
// check_render_size throws InputError naming the sizes when it exceeds `budget_bytes`;
// `capped` says whether that is --max-memory.
uint64_t estimate_render_bytes(const SceneData& scene, bool gl);
void check_render_size(const SceneData& scene, bool gl, uint64_t budget_bytes, bool capped);

}  // namespace abcube
