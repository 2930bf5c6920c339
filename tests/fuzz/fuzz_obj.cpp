// libFuzzer harness: the bytes are a Wavefront OBJ file, optionally followed by a line
// "#MTL" and the MTL file it may name as "mtllib in.mtl". Both are written to a private
// folder (the loader reads files: one code path, the one scenes use) and loaded as the
// one mesh object of a scene, with its MTL materials, confined to that folder and to
// 200,000 triangles.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_checks.hpp"
#include "scene/scene_load.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fz = abcube::fuzz;
  static const abcube::LoadLimits limits = [] {
    abcube::LoadLimits l;
    l.root = fz::scratch_dir();
    l.max_triangles = 200000;
    return l;
  }();
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n#MTL\n";
  const size_t split = bytes.find(separator);
  const size_t obj_size = split == std::string::npos ? size : split + 1;
  const size_t mtl_start = split == std::string::npos ? size : split + separator.size();
  fz::write_file(limits.root + "/in.obj", data, obj_size);
  fz::write_file(limits.root + "/in.mtl", data + mtl_start, size - mtl_start);
  const std::string scene =
      R"({"version": 1, "camera": {"position": [0, 1, -4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 60, "width": 8, "height": 8},
"objects": [{"type": "mesh", "file": "in.obj"}]})";
  fz::expect_input_error_or_success(
      [&] { fz::check_scene(abcube::load_scene_text(scene, "scene.json", limits.root, limits)); }, "scene.json");
  return 0;
}
