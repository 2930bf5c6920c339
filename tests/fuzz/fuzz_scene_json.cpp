// libFuzzer harness: the bytes are a scene file (scene-format.md), loaded by
// load_scene_text as "scene.json" from a folder holding a small mesh that the scene may
// name, meshes/octahedron.obj with its octahedron.mtl (where the repository's scenes find
// theirs). Files outside that folder are refused (LoadLimits::root)
// and scenes over 200,000 triangles too, so that an input costs milliseconds.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "fuzz_checks.hpp"
#include "scene/scene_load.hpp"

namespace {

const char* const MESH =
    "mtllib octahedron.mtl\n"
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nvn 0 0 1\n"
    "usemtl red\nf 1 3 5\nf 3 2 5\nf 2 4 5//1\nf 4 1 5//1\n"
    "usemtl blue\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6 2\n";
const char* const MTL =
    "newmtl red\nKd 0.8 0.1 0.1\nKs 0.5 0.5 0.5\nNs 64\nd 1\n\nnewmtl blue\nKd 0.1 0.2 0.8\nNi 1.33\n";

const abcube::LoadLimits& limits() {
  static const abcube::LoadLimits l = [] {
    namespace fz = abcube::fuzz;
    const std::string& dir = fz::scratch_dir();
    std::filesystem::create_directory(dir + "/meshes");
    fz::write_file(dir + "/meshes/octahedron.obj", reinterpret_cast<const uint8_t*>(MESH),
                   std::char_traits<char>::length(MESH));
    fz::write_file(dir + "/meshes/octahedron.mtl", reinterpret_cast<const uint8_t*>(MTL),
                   std::char_traits<char>::length(MTL));
    abcube::LoadLimits out;
    out.root = dir;
    out.max_triangles = 200000;
    return out;
  }();
  return l;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const abcube::LoadLimits& l = limits();
  abcube::fuzz::expect_input_error_or_success(
      [&] { abcube::fuzz::check_scene(abcube::load_scene_text(text, "scene.json", l.root, l)); }, "scene.json");
  return 0;
}
