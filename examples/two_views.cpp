// Two views of one scene through the abcube library: the scene is loaded once and one
// Renderer renders it from two camera positions; the second render reuses the per-scene
// data the first built (its scene_data.built_by_this_render is 0).
//
//   two_views [OUT_DIR] [SCENE.json]      (defaults: "." and scenes/cornell.json)
//
// Build it against an installed abcube:
//   find_package(abcube REQUIRED)
//   target_link_libraries(two_views PRIVATE abcube::abcube)
#include <array>
#include <cstdio>
#include <exception>
#include <string>

#include <abcube/renderer.hpp>

int main(int argc, char** argv) {
  const std::string out_dir = argc > 1 ? argv[1] : ".";
  const std::string scene_file = argc > 2 ? argv[2] : "scenes/cornell.json";
  try {
    // Load and validate the scene once; every render shares it.
    const abcube::Scene scene = abcube::Scene::load(scene_file);

    // One Renderer for both views (GL, if a method needs it, opens on first use).
    abcube::Renderer renderer;

    // A small image: only the keys given override the scene's camera.
    abcube::RenderOptions options;
    options.method = "abuffer";
    options.cube_resolution = 128;
    options.camera.width = 160;
    options.camera.height = 120;

    const std::array<std::array<double, 3>, 2> positions{{{0.0, 1.0, 2.45}, {0.6, 1.4, 1.8}}};
    for (size_t view = 0; view < positions.size(); ++view) {
      options.camera.position = positions[view];
      const abcube::RenderResult result = renderer.render(scene, options);
      const std::string path = out_dir + "/view" + std::to_string(view) + ".png";
      abcube::write_image(path, result.image);  // sRGB-encoded 8-bit PNG, written atomically
      std::printf("%s: %.1f ms, scene_data.built_by_this_render = %d\n", path.c_str(), result.stats.total_ms,
                  result.stats.scene_data_built);
    }
    return 0;
  } catch (const abcube::InputError& e) {  // a bad scene or option: one line naming it
    std::fprintf(stderr, "two_views: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {  // anything else (no GL, disk full, ...)
    std::fprintf(stderr, "two_views: error: %s\n", e.what());
    return 1;
  }
}
