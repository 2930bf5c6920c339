// Conversions between Python objects and the library's types (py_convert.hpp).
#include "py_convert.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <vector>

#include <pybind11/stl.h>

namespace abcube {

py::array image_to_array(Image&& image) {
  // The vector moves into a capsule that numpy frees with the array: no copy, no leak.
  auto pixels = std::make_unique<std::vector<float>>(std::move(image.data));
  const float* data = pixels->data();
  py::capsule owner(pixels.get(), [](void* p) { delete static_cast<std::vector<float>*>(p); });
  pixels.release();
  std::vector<py::ssize_t> shape = {image.height, image.width};
  if (image.channels != 1) shape.push_back(image.channels);
  return py::array_t<float>(shape, data, owner);
}

Image array_to_image(const py::handle& array, const std::string& what) {
  // Any numeric array-like, made a C-contiguous float32 array (a view when it already is one).
  // Integer pixels (uint8 PNG codes) are refused: the values are linear light in floats.
  const py::array any = py::array::ensure(array);
  if (!any || (any.dtype().kind() != 'f' && any.dtype().kind() != 'i' && any.dtype().kind() != 'u')) {
    throw InputError(what + ": must be a float array (H x W x C), got " + type_name(array));
  }
  if (any.dtype().kind() != 'f' && py::isinstance<py::array>(array)) {
    throw InputError(what + ": must hold floats (linear values), got " + std::string(py::str(any.dtype())) + " pixels");
  }
  using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
  const FloatArray pixels = FloatArray::ensure(any);
  const py::ssize_t ndim = pixels.ndim();
  const py::ssize_t channels = ndim == 3 ? pixels.shape(2) : 1;
  if ((ndim != 2 && ndim != 3) || channels < 1 || channels > 4 || pixels.shape(0) < 1 || pixels.shape(1) < 1) {
    std::string shape;
    for (py::ssize_t k = 0; k < ndim; ++k) shape += (k ? " x " : "") + std::to_string(pixels.shape(k));
    throw InputError(what + ": must have shape H x W or H x W x C with C in 1..4, got (" + shape + ")");
  }
  Image image(static_cast<int>(pixels.shape(1)), static_cast<int>(pixels.shape(0)), static_cast<int>(channels));
  std::copy(pixels.data(), pixels.data() + pixels.size(), image.data.begin());
  return image;
}

std::string type_name(const py::handle& value) { return py::str(py::type::handle_of(value).attr("__name__")); }

std::string path_arg(const py::handle& value, const std::string& what) {
  // os.fspath accepts str and os.PathLike (pathlib.Path); bytes are refused.
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (!py::hasattr(value, "__fspath__")) {
    throw InputError(what + ": must be a path (str or os.PathLike), got " + type_name(value));
  }
  py::object path = py::module_::import("os").attr("fspath")(value);
  if (!py::isinstance<py::str>(path)) {
    throw InputError(what + ": must be a str path, got " + type_name(path));
  }
  return path.cast<std::string>();
}

std::string string_arg(const py::handle& value, const std::string& what) {
  if (!py::isinstance<py::str>(value)) {
    throw InputError(what + ": must be a string, got " + type_name(value));
  }
  return value.cast<std::string>();
}

bool bool_arg(const py::handle& value, const std::string& what) {
  // True/False (and numpy.bool_); 0 and 1 would hide a swapped argument.
  if (py::isinstance<py::bool_>(value) || type_name(value) == "bool_") {
    return value.cast<bool>();
  }
  throw InputError(what + ": must be True or False, got " + type_name(value));
}

namespace {

// A Python int or numpy integer that fits T; never a float or a bool. `kind` names what is
// expected in the message.
template <class T>
T integer_arg(const py::handle& value, const std::string& what, const char* kind, const char* range_message) {
  if (py::isinstance<py::bool_>(value) || !py::hasattr(value, "__index__")) {
    throw InputError(what + ": must be " + kind + ", got " + type_name(value));
  }
  try {
    return py::int_(py::reinterpret_borrow<py::object>(value)).cast<T>();
  } catch (const py::cast_error&) {
    throw InputError(what + ": " + range_message + ", got " + std::string(py::str(value)));
  }
}

}  // namespace

int int_arg(const py::handle& value, const std::string& what) {
  return integer_arg<int>(value, what, "an integer", "integer out of range");
}

uint64_t unsigned_arg(const py::handle& value, const std::string& what) {
  return integer_arg<uint64_t>(value, what, "an integer >= 0", "must be an integer >= 0");
}

// A Python value as JSON text, for the option table: bool, int, float, str, os.PathLike,
// sequences (lists, tuples, numpy arrays) and dicts; numpy scalars by their .item().
std::string json_text(const py::handle& v, const std::string& what) {
  if (v.is_none()) return "null";
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(v)) return std::string(py::str(v));
  if (py::isinstance<py::float_>(v)) {
    const double x = v.cast<double>();
    if (!std::isfinite(x)) throw InputError(what + ": must be a finite number, got " + std::string(py::repr(v)));
    return nlohmann::json(x).dump();
  }
  if (py::isinstance<py::str>(v)) return nlohmann::json(v.cast<std::string>()).dump();
  if (py::hasattr(v, "__fspath__")) return nlohmann::json(path_arg(v, what)).dump();
  if (py::isinstance<py::dict>(v)) {
    std::string out = "{";
    for (const auto& item : py::reinterpret_borrow<py::dict>(v)) {
      const std::string key = string_arg(item.first, what + " key");
      out += (out.size() > 1 ? "," : "") + nlohmann::json(key).dump() + ":" + json_text(item.second, what + "." + key);
    }
    return out + "}";
  }
  if (py::hasattr(v, "item") && py::hasattr(v, "dtype") && py::getattr(v, "ndim").cast<int>() == 0) {
    return json_text(v.attr("item")(), what);  // a numpy scalar
  }
  if (py::isinstance<py::sequence>(v) || py::hasattr(v, "tolist")) {
    const py::object list = py::hasattr(v, "tolist") ? v.attr("tolist")() : py::reinterpret_borrow<py::object>(v);
    std::string out = "[";
    for (const py::handle x : list) out += (out.size() > 1 ? "," : "") + json_text(x, what + "[]");
    return out + "]";
  }
  throw InputError(what + ": unsupported value of type " + type_name(v));
}

SceneOverrides overrides_arg(const py::handle& set) {
  SceneOverrides out;
  if (set.is_none()) return out;
  if (!py::isinstance<py::dict>(set)) {
    throw InputError("set: must be a dict of scene values {\"camera.fov_y\": 30, ...}, got " + type_name(set));
  }
  for (const auto& item : py::reinterpret_borrow<py::dict>(set)) {
    const std::string path = string_arg(item.first, "set key");
    out.push_back({path, json_text(item.second, "set[" + path + "]")});
  }
  return out;
}

}  // namespace abcube
