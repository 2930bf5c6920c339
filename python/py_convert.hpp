// Conversions between Python objects and the library's types, shared by the bindings.
// A Python value of the wrong kind is bad input: InputError (abcube.SceneError) naming the
// argument, as the CLI names its option.
#pragma once
#include <array>
#include <cstdint>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <abcube/image.hpp>
#include <abcube/renderer.hpp>
#include <abcube/scene.hpp>

namespace abcube {

namespace py = pybind11;

// The pixels as a float32 numpy array that owns them (moved, not copied): H x W x C, or
// H x W for a 1-channel image.
py::array image_to_array(Image&& image);

// A numpy array (or anything numpy converts) of shape H x W or H x W x C, C in 1..4, as a
// float Image (a copy). `what` names the argument in the message of a bad one.
Image array_to_image(const py::handle& array, const std::string& what);

// A str or os.PathLike as a path string.
std::string path_arg(const py::handle& value, const std::string& what);

// Typed reads of one argument; `what` names it in the InputError of a wrong type.
std::string string_arg(const py::handle& value, const std::string& what);
bool bool_arg(const py::handle& value, const std::string& what);
int int_arg(const py::handle& value, const std::string& what);
uint64_t unsigned_arg(const py::handle& value, const std::string& what);

// A Python value as JSON text (bool, int, float, str, os.PathLike, sequences, numpy
// arrays and scalars, dicts); InputError naming `what` for a NaN or another type.
std::string json_text(const py::handle& value, const std::string& what);

// A dict {"camera.fov_y": 30, ...} (or None) as scene overrides (<abcube/scene.hpp>).
SceneOverrides overrides_arg(const py::handle& set);

// The Python type name of a value, for messages ("got str").
std::string type_name(const py::handle& value);

// Module parts, one per concept (py_image.cpp, py_scene.cpp, py_renderer.cpp).
void bind_image(py::module_& m);
void bind_scene(py::module_& m);
void bind_renderer(py::module_& m);

}  // namespace abcube
