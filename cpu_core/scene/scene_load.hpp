// Loading a scene file (../shared/scene-format.md, version 1) into a Scene.
#pragma once
#include <cstdint>
#include <string>

#include "scene/scene.hpp"

namespace abcube {

// Parses, validates, tessellates and transforms. Throws InputError with one line that
// names the place: "FILE:LINE:COL: ..." for JSON syntax, "FILE: objects[3].radius: ..."
// for values. Unknown fields, NaN/inf, degenerate cameras, missing mesh files, unknown
// materials and out-of-range weights are errors; zero-area triangles are dropped and
// counted in Scene::dropped_triangles.
Scene load_scene(const std::string& path);

// Same, from text already in memory; `name` stands for the file in messages and
// `base_dir` resolves relative mesh paths.
Scene load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir);

// Bytes a render of this scene needs at its camera size and cube resolution (images,
// cube faces, triangles); throws InputError naming the sizes when it exceeds
// `budget_bytes` (pass available_memory_bytes()).
uint64_t estimate_render_bytes(const Scene& scene);
void check_render_size(const Scene& scene, uint64_t budget_bytes);

}  // namespace abcube
