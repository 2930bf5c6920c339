// abcube.Scene and its loaders: load_scene (a file), scene_from_dict and scene_from_json
// (in memory), with the limits for untrusted scenes (include/abcube/scene.hpp).
#include <string>

#include <pybind11/stl.h>

#include "py_convert.hpp"

namespace abcube {

namespace {

SceneLimits limits_arg(const py::handle& root, const py::handle& max_triangles, const py::handle& max_memory_mib,
                       const py::handle& threads) {
  SceneLimits limits;
  if (!root.is_none()) limits.root = path_arg(root, "root");
  limits.max_triangles = unsigned_arg(max_triangles, "max_triangles");
  limits.max_memory_mib = unsigned_arg(max_memory_mib, "max_memory_mib");
  const uint64_t t = unsigned_arg(threads, "threads");
  if (t > 4096) throw InputError("threads: must be in [0, 4096], got " + std::to_string(t));
  limits.threads = static_cast<int>(t);
  return limits;
}

Scene load_scene(const py::handle& path, const py::handle& root, const py::handle& max_triangles,
                 const py::handle& max_memory_mib, const py::handle& set, const py::handle& threads) {
  const std::string file = path_arg(path, "load_scene: path");
  const SceneLimits limits = limits_arg(root, max_triangles, max_memory_mib, threads);
  const SceneOverrides overrides = overrides_arg(set);
  py::gil_scoped_release release;
  return Scene::load(file, limits, overrides);
}

Scene scene_from_json(const py::handle& text, const py::handle& name, const py::handle& base_dir,
                      const py::handle& root, const py::handle& max_triangles, const py::handle& max_memory_mib,
                      const py::handle& threads) {
  const std::string json_text = string_arg(text, "scene_from_json: text");
  const std::string scene_name = string_arg(name, "name");
  const std::string dir = path_arg(base_dir, "base_dir");
  const SceneLimits limits = limits_arg(root, max_triangles, max_memory_mib, threads);
  py::gil_scoped_release release;
  return Scene::from_json(json_text, scene_name, dir, limits);
}

Scene scene_from_dict(const py::handle& scene, const py::handle& name, const py::handle& base_dir,
                      const py::handle& root, const py::handle& max_triangles, const py::handle& max_memory_mib,
                      const py::handle& threads) {
  // Python's json writes the text; NaN and infinity are refused here (not JSON), the rest is
  // validated by the loader, whose messages name the field path.
  if (!py::isinstance<py::dict>(scene)) {
    throw InputError(string_arg(name, "name") + ": the scene must be a dict, got " + type_name(scene));
  }
  py::object text;
  try {
    text = py::module_::import("json").attr("dumps")(scene, py::arg("allow_nan") = false);
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError) && !e.matches(PyExc_TypeError)) throw;
    throw InputError(string_arg(name, "name") + ": not a JSON scene: " + std::string(py::str(e.value())));
  }
  return scene_from_json(text, name, base_dir, root, max_triangles, max_memory_mib, threads);
}

std::string scene_repr(const Scene& s) {
  return "<abcube.Scene '" + s.name() + "' " + std::to_string(s.width()) + "x" + std::to_string(s.height()) + ", " +
         std::to_string(s.object_count()) + " objects, " + std::to_string(s.triangle_count()) + " triangles, method " +
         s.method() + ">";
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<Scene>(m, "Scene",
                    R"doc(A validated, tessellated scene (docs/scene-format.md). Immutable:
any number of threads and Renderers may render one Scene at once; its per-scene data
(mesh neighbours, lens fits, the tracer's BVH) is built once, by the first render that
needs it. Made by load_scene, scene_from_dict or scene_from_json.)doc")
      .def_property_readonly("name", &Scene::name, "The file as given (or the name), for messages.")
      .def_property_readonly("width", &Scene::width, "Camera image width in pixels.")
      .def_property_readonly("height", &Scene::height, "Camera image height in pixels.")
      .def_property_readonly("triangle_count", &Scene::triangle_count)
      .def_property_readonly("object_count", &Scene::object_count)
      .def_property_readonly("method", &Scene::method, "render.method of the scene.")
      .def_property_readonly("cube_resolution", &Scene::cube_resolution,
                             "render.cube_resolution N (texels per cube face edge).")
      .def_property_readonly("max_depth", &Scene::max_depth, "render.max_depth (bounces).")
      .def_property_readonly("warnings", &Scene::warnings,
                             "What loaded but is likely a mistake (a mesh without triangles), one line each.")
      .def("__repr__", &scene_repr);

  m.def("load_scene", &load_scene, py::arg("path"), py::arg("root") = py::none(), py::arg("max_triangles") = 0,
        py::arg("max_memory_mib") = 0, py::arg("set") = py::none(), py::arg("threads") = 0,
        R"doc(Loads a scene file, or a model file (.gltf, .glb, .obj: the model alone, framed and
lit, 640 x 480, its own camera if it has one; docs/models-and-textures.md). Untrusted scenes:
`root` confines every file the scene references to that folder, `max_triangles` (> 0) caps
its size, `max_memory_mib` (> 0, else the memory available) the memory its triangles may
take; all are refused before anything is allocated. `set`: a dict {"camera.fov_y": 30,
"lights[0].position": [1, 4, 2], ...} of the file's values replaced before it is read, as
`abcube render --set`. `threads`: the cores the load may use (0 = every core; a large OBJ or
glTF mesh is read on them). A bad scene raises SceneError naming the place ("scene.json:12:5:
..." or "scene.json: objects[3].radius: ...").)doc");
  m.def("scene_from_dict", &scene_from_dict, py::arg("scene"), py::arg("name") = "<dict>", py::arg("base_dir") = ".",
        py::arg("root") = py::none(), py::arg("max_triangles") = 0, py::arg("max_memory_mib") = 0,
        py::arg("threads") = 0,
        R"doc(A scene from a dict in the scene file's format. `name` stands for the file in
messages ("<dict>: objects[0].radius: ..."); relative mesh paths resolve against
`base_dir`. Raises SceneError as load_scene does.)doc");
  m.def("scene_from_json", &scene_from_json, py::arg("text"), py::arg("name") = "<json>", py::arg("base_dir") = ".",
        py::arg("root") = py::none(), py::arg("max_triangles") = 0, py::arg("max_memory_mib") = 0,
        py::arg("threads") = 0, "A scene from JSON text; as scene_from_dict.");
}

}  // namespace abcube
