// libFuzzer harness: the bytes are a glTF 2.0 model. Beginning with the magic "glTF": a
// binary .glb, written as in.glb. Otherwise the JSON of a .gltf, optionally followed by a
// line "#BIN" and the bytes of the buffer it may name as "in.bin"; both written to a
// private folder (the loader reads files: one code path, the one scenes use) and loaded as
// the one gltf object of a scene, confined to that folder and to 200,000 triangles.
#include <cstddef>
#include <cstdint>
#include <cstring>
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
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  std::string model = "in.glb";
  if (binary) {
    fz::write_file(limits.root + "/in.glb", data, size);
  } else {
    model = "in.gltf";
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    const std::string separator = "\n#BIN\n";
    const size_t split = bytes.find(separator);
    const size_t json_size = split == std::string::npos ? size : split + 1;
    const size_t bin_start = split == std::string::npos ? size : split + separator.size();
    fz::write_file(limits.root + "/in.gltf", data, json_size);
    fz::write_file(limits.root + "/in.bin", data + bin_start, size - bin_start);
  }
  const std::string scene =
      R"({"version": 1, "camera": {"position": [0, 1, -4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 60, "width": 8, "height": 8},
"objects": [{"type": "gltf", "file": ")" +
      model + R"("}]})";
  fz::expect_input_error_or_success(
      [&] { fz::check_scene(abcube::load_scene_text(scene, "scene.json", limits.root, limits)); }, "scene.json");
  return 0;
}
