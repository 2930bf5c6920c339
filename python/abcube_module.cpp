// The `abcube` Python module (docs/python.md): the library API for Python, with the
// library's exceptions mapped to Python ones and numpy arrays for images.
#include <string>

#include "py_convert.hpp"

namespace abcube {

namespace {

// "abcube 1.2.3 (git abc)" -> "1.2.3".
std::string version_number(const std::string& full) {
  std::string v = full.rfind("abcube ", 0) == 0 ? full.substr(7) : full;
  return v.substr(0, v.find(' '));
}

// InputError -> SceneError (a ValueError), RenderTimeout -> RenderTimeout (a RuntimeError),
// RuntimeFailure -> RuntimeError (pybind11's std::exception default), InternalError ->
// RuntimeError naming it a bug. The messages are the library's, location included.
void register_exceptions(py::module_& m) {
  py::register_exception<InputError>(m, "SceneError", PyExc_ValueError).doc() =
      "A bad scene or argument; the message names the place (file:line:col, or the "
      "field path such as objects[3].radius). A subclass of ValueError.";
  py::register_exception<RenderTimeout>(m, "RenderTimeout", PyExc_RuntimeError).doc() =
      "A render ran past its timeout (seconds). A subclass of RuntimeError.";
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const InternalError& e) {
      PyErr_SetString(PyExc_RuntimeError, (std::string("abcube internal error: ") + e.what()).c_str());
    }
  });
}

}  // namespace

}  // namespace abcube

PYBIND11_MODULE(abcube, m) {
  // numpy's C API is set up here, once, with the GIL held: set up lazily by the first image
  // two threads return at once, its import releases the GIL halfway and the other thread
  // waits on the half-made API while holding it (a deadlock).
  (void)pybind11::detail::npy_api::get();
  m.doc() = R"doc(abcube: a headless hybrid renderer (cube-map A-buffer searches, an exact ray
tracer, a GPU Z-buffer path) for Python.

    scene = abcube.load_scene("scenes/cornell.json")   # or abcube.scene_from_dict({...})
    r = abcube.Renderer()                               # gl="auto", threads=0 (every core)
    img = r.render(scene, method="abuffer", cube_res=256, width=320, height=240,
                   camera={"position": [0, 1, 1.5], "look_at": [0, 0.8, -1]})  # inside the room
    # img: float32 H x W x 3, linear RGB
    abcube.write_image("out.exr", img)

Threads: the GIL is released while a render runs; renders on different Renderer objects
run concurrently, calls on one Renderer are serialized (see help(abcube.Renderer)).
Errors: SceneError (a ValueError) for a bad scene or argument, RenderTimeout (a
RuntimeError) past a render's timeout, RuntimeError for other failures.)doc";
  abcube::register_exceptions(m);
  m.attr("__version__") = abcube::version_number(abcube::version_string());
  m.def("version_string", &abcube::version_string,
        "The full version, as `abcube --version` prints it (with the git commit when built from one).");
  abcube::bind_image(m);
  abcube::bind_scene(m);
  abcube::bind_renderer(m);
}
