// libFuzzer harness: the bytes are a Wavefront OBJ file, optionally followed by a line
// "#MTL" and the MTL file it may name as "mtllib in.mtl". Both are written to a private
// folder (the loader reads files: one code path, the one scenes use) and loaded as the
// one mesh object of a scene, with its MTL materials, confined to that folder and to
// 200,000 triangles. The OBJ text is also read on 3 threads in small blocks, which must
// give what one pass over it gives (obj_text.hpp, PARALLEL READING).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_checks.hpp"
#include "scene/obj_text.hpp"
#include "scene/scene_load.hpp"

namespace {

bool same(const abcube::ObjText& a, const abcube::ObjText& b) {
  if (a.v != b.v || a.vn != b.vn || a.vt != b.vt || a.face_sizes != b.face_sizes || a.lines != b.lines ||
      a.error_line != b.error_line || a.error != b.error || a.corners.size() != b.corners.size() ||
      a.statements.size() != b.statements.size()) {
    return false;
  }
  for (size_t k = 0; k < a.corners.size(); ++k) {
    if (a.corners[k].v != b.corners[k].v || a.corners[k].vt != b.corners[k].vt || a.corners[k].vn != b.corners[k].vn)
      return false;
  }
  for (size_t k = 0; k < a.statements.size(); ++k) {
    if (a.statements[k].kind != b.statements[k].kind || a.statements[k].text != b.statements[k].text ||
        a.statements[k].faces_before != b.statements[k].faces_before)
      return false;
  }
  return true;
}

}  // namespace

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
  const abcube::ObjText one = abcube::parse_obj_text(std::string(reinterpret_cast<const char*>(data), obj_size));
  const abcube::ObjText parts = abcube::read_obj_text(limits.root + "/in.obj", abcube::ObjReading{3, 61, 7});
  if (!same(one, parts)) fz::broken("in.obj read in parts differs from one pass over it");
  const std::string scene =
      R"({"version": 1, "camera": {"position": [0, 1, -4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 60, "width": 8, "height": 8},
"objects": [{"type": "mesh", "file": "in.obj"}]})";
  fz::expect_input_error_or_success(
      [&] { fz::check_scene(abcube::load_scene_text(scene, "scene.json", limits.root, limits)); }, "scene.json");
  return 0;
}
