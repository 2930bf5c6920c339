// Loading a scene file (../shared/scene-format.md, version 1) into a SceneData.
#pragma once
#include <cstdint>
#include <string>

#include "scene/scene_data.hpp"

namespace abcube {

// Parses, validates, tessellates and transforms. Throws InputError with one line that
// names the place: "FILE:LINE:COL: ..." for JSON syntax, "FILE: objects[3].radius: ..."
// for values. Unknown fields, NaN/inf, degenerate cameras, missing mesh files, unknown
// materials and out-of-range weights are errors; zero-area triangles are dropped and
// counted in SceneData::dropped_triangles.
SceneData load_scene(const std::string& path);

// Same, from text already in memory; `name` stands for the file in messages and
// `base_dir` resolves relative mesh paths.
SceneData load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir);

// Bytes a render of this scene needs at its camera size and cube resolution (images,
// cube faces, triangles); throws InputError naming the sizes when it exceeds
// `budget_bytes` (pass available_memory_bytes()).
uint64_t estimate_render_bytes(const SceneData& scene);
void check_render_size(const SceneData& scene, uint64_t budget_bytes);

}  // namespace abcube
