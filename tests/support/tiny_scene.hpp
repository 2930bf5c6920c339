// A tiny scene for the soak and overhead benchmarks and the API tests: a floor, a mirror
// wall, a glass sphere and a box under one shadowing light, so every method runs every
// kind of search (reflection, refraction, shadow) on a few hundred triangles.
#pragma once
#include <string>

namespace abcube {

// The scene as JSON text, at `width` x `height` pixels and cube resolution `cube_res`.
inline std::string tiny_scene_json(int width, int height, int cube_res) {
  return R"({
  "version": 1,
  "camera": { "position": [0, 1.2, 3], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y": 50,
              "width": )" +
         std::to_string(width) + R"(, "height": )" + std::to_string(height) + R"( },
  "background": [0.05, 0.07, 0.1],
  "ambient": [0.1, 0.1, 0.1],
  "lights": [ { "type": "point", "position": [-2, 4, 3], "color": [1, 1, 1], "cast_shadows": true } ],
  "materials": {
    "floor":  { "color": [0.75, 0.75, 0.7] },
    "red":    { "color": [0.8, 0.15, 0.1], "specular": 0.4, "shininess": 48 },
    "mirror": { "color": [0.1, 0.1, 0.1], "specular": 0.5, "shininess": 64, "reflect": 0.85 },
    "glass":  { "color": [1, 1, 1], "diffuse": 0.0, "specular": 0.6, "shininess": 96, "transmit": 0.9, "ior": 1.5 }
  },
  "objects": [
    { "type": "quad", "vertices": [[-3, 0, -3], [-3, 0, 3], [3, 0, 3], [3, 0, -3]], "material": "floor" },
    { "type": "quad", "vertices": [[-2, 0, -1.5], [2, 0, -1.5], [2, 2, -1.5], [-2, 2, -1.5]], "material": "mirror" },
    { "type": "sphere", "center": [0.4, 0.5, 0.2], "radius": 0.5, "segments": 16, "material": "glass" },
    { "type": "box", "min": [-0.3, 0, -0.3], "max": [0.3, 0.6, 0.3], "material": "red",
      "transform": { "translate": [-0.8, 0, -0.4], "rotate_deg": [0, 30, 0] } }
  ],
  "render": { "method": "abuffer", "cube_resolution": )" +
         std::to_string(cube_res) + R"(, "max_depth": 3 }
})";
}

}  // namespace abcube
