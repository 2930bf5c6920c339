// The scene file's sections (scene_load_state.hpp): camera, lights, materials, render
// settings, an object's transform; each value checked where it is read, every message
// naming its place.
#include <algorithm>
#include <cmath>

#include "base/error.hpp"
#include "base/samples.hpp"
#include "scene/framing.hpp"
#include "scene/scene_load_state.hpp"

namespace abcube::detail {

namespace {

constexpr int MAX_IMAGE_SIDE = 32768;
constexpr int MAX_CUBE_RESOLUTION = 16384;
constexpr int MAX_BOUNCES = 64;

}  // namespace

CameraSection read_camera(const Fields& f) {
  CameraSection section;
  Camera& c = section.camera;
  const Source& src = f.src();
  if (const Json* frame = f.find("frame")) {
    const std::string what = read_string(src, *frame, f.at("frame"));
    if (what != "all") fail(src, f.at("frame"), "must be \"all\" (the whole scene), got " + describe(*frame));
    for (const char* key : {"position", "look_at"}) {
      if (f.find(key)) fail(src, f.at(key), "must not be given with \"frame\" (framing places the camera)");
    }
    section.frame = true;
    section.direction = f.vec3("direction", section.direction);
    if (!(glm::length(section.direction) > 0))
      fail(src, f.at("direction"), "must be nonzero, got " + describe(section.direction));
  } else {
    if (f.find("direction")) fail(src, f.at("direction"), "is read only with \"frame\": \"all\"");
    c.position = f.vec3("position");
    c.look_at = f.vec3("look_at");
  }
  c.up = f.vec3("up", c.up);
  c.fov_y_deg = f.number("fov_y", c.fov_y_deg);
  c.width = f.integer("width", c.width, 1, MAX_IMAGE_SIDE);
  c.height = f.integer("height", c.height, 1, MAX_IMAGE_SIDE);
  if (!(c.fov_y_deg > 0 && c.fov_y_deg < 180)) {
    fail(src, f.at("fov_y"), "must be > 0 and < 180 (degrees), got " + format_number(c.fov_y_deg));
  }
  const double up_length = glm::length(c.up);
  if (!(up_length > 0)) fail(src, f.at("up"), "must be nonzero, got " + describe(c.up));
  if (section.frame) return section;  // up parallel to direction: frame_camera picks another
  const glm::dvec3 view = c.look_at - c.position;
  const double scale = std::max(glm::length(c.position), glm::length(c.look_at));
  if (!(glm::length(view) > 1e-12 * scale)) {
    fail(src, f.at("look_at"), "must differ from camera.position, got " + describe(c.look_at));
  }
  // sin of the angle between up and the view direction
  if (!(glm::length(glm::cross(glm::normalize(view), c.up / up_length)) > 1e-6)) {
    fail(src, f.at("up"), "must not be parallel to the view direction (look_at - position), got " + describe(c.up));
  }
  return section;
}

PointLight read_light(const Fields& f) {
  const std::string type = read_string(f.src(), f.need("type"), f.at("type"));
  if (type != "point") fail(f.src(), f.at("type"), "must be \"point\", got " + describe(Json(type)));
  PointLight l;
  l.position = f.vec3("position");
  l.color = f.vec3("color", l.color);
  check_non_negative(f.src(), f.at("color"), l.color);
  if (const Json* v = f.find("cast_shadows")) l.cast_shadows = read_bool(f.src(), *v, f.at("cast_shadows"));
  return l;
}

// Phong material with the format's defaults (docs/scene-format.md "materials").
Material read_material(const Fields& f, const std::string& name) {
  Material m;
  m.name = name;
  m.color = f.vec3("color", m.color);
  check_non_negative(f.src(), f.at("color"), m.color);
  m.ambient = f.number_in("ambient", m.ambient, 0, 1);
  m.diffuse = f.number_in("diffuse", m.diffuse, 0, 1);
  m.specular = f.number_in("specular", m.specular, 0, 1);
  m.shininess = f.number("shininess", m.shininess);
  if (m.shininess < 0) fail(f.src(), f.at("shininess"), "must be >= 0, got " + format_number(m.shininess));
  m.reflect = f.number_in("reflect", m.reflect, 0, 1);
  m.transmit = f.number_in("transmit", m.transmit, 0, 1);
  m.ior = f.number("ior", m.ior);
  if (m.ior < 1) fail(f.src(), f.at("ior"), "must be >= 1, got " + format_number(m.ior));
  m.opacity = f.number_in("opacity", m.opacity, 0, 1);
  return m;
}

RenderSettings read_render(const Fields& f, const std::vector<std::string>& methods) {
  RenderSettings r;
  if (const Json* v = f.find("method")) {
    r.method = read_string(f.src(), *v, f.at("method"));
    const bool known = methods.empty() ? !r.method.empty() : std::count(methods.begin(), methods.end(), r.method) > 0;
    if (!known) {
      fail(f.src(), f.at("method"),
           (methods.empty() ? std::string("must be a method's name") : "must be one of " + join(methods, ", ")) +
               ", got " + describe(*v));
    }
  }
  r.cube_resolution = f.integer("cube_resolution", r.cube_resolution, 1, MAX_CUBE_RESOLUTION);
  r.max_depth = f.integer("max_depth", r.max_depth, 0, MAX_BOUNCES);
  if (const Json* v = f.find("fresnel")) r.fresnel = read_bool(f.src(), *v, f.at("fresnel"));
  if (const Json* v = f.find("error_target")) {
    r.error_target = read_number(f.src(), *v, f.at("error_target"));
    check_range(f.src(), f.at("error_target"), r.error_target, 1e-12, 0.5);
  }
  if (const Json* v = f.find("target_db")) {
    r.target_db = read_number(f.src(), *v, f.at("target_db"));
    check_range(f.src(), f.at("target_db"), r.target_db, MIN_TARGET_DB, MAX_TARGET_DB);
  }
  r.samples = f.integer("samples", r.samples, 1, MASK_SAMPLES);
  if (!is_sample_rung(r.samples)) {
    fail(f.src(), f.at("samples"), "must be 1, 2, 4, 8, 16 or 32, got " + std::to_string(r.samples));
  }
  return r;
}

Transform read_transform(const Fields& f) {
  Transform t;
  t.translate = f.vec3("translate", t.translate);
  t.rotate_deg = f.vec3("rotate_deg", t.rotate_deg);
  if (const Json* s = f.find("scale")) {
    t.scale =
        s->is_number() ? glm::dvec3(read_number(f.src(), *s, f.at("scale"))) : read_vec3(f.src(), *s, f.at("scale"));
    for (int i = 0; i < 3; ++i) {
      if (t.scale[i] == 0) {
        fail(f.src(), s->is_number() ? f.at("scale") : index_path(f.at("scale"), static_cast<size_t>(i)),
             "must be nonzero, got 0");
      }
    }
  }
  return t;
}

}  // namespace abcube::detail
