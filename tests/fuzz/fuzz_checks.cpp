#include "fuzz_checks.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <typeinfo>

#include <abcube/error.hpp>

#include "reference/raytrace.hpp"
#include "scene/radiance.hpp"

namespace abcube::fuzz {

void broken(const std::string& what) {
  std::fprintf(stderr, "fuzz check failed: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

namespace {

// ABCUBE_FUZZ_VERBOSE=1: each input's outcome on stderr (to see what seeds reach).
bool verbose() {
  static const bool v = std::getenv("ABCUBE_FUZZ_VERBOSE") != nullptr;
  return v;
}

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const glm::vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

}  // namespace

void check_scene(const SceneData& scene) {
  const Camera& c = scene.camera;
  if (!finite(c.position) || !finite(c.look_at) || !finite(c.up) || !std::isfinite(c.fov_y_deg))
    broken("camera not finite");
  if (c.width <= 0 || c.height <= 0) broken("camera size not positive");
  if (!finite(scene.background) || !finite(scene.ambient)) broken("background or ambient not finite");
  for (const PointLight& l : scene.lights) {
    if (!finite(l.position) || !finite(l.color)) broken("light not finite");
  }
  for (const Material& m : scene.materials) {
    if (!finite(m.color) || !std::isfinite(m.ambient) || !std::isfinite(m.diffuse) || !std::isfinite(m.specular) ||
        !std::isfinite(m.shininess) || !std::isfinite(m.reflect) || !std::isfinite(m.transmit) ||
        !std::isfinite(m.ior) || !std::isfinite(m.opacity)) {
      broken("material " + m.name + " not finite");
    }
  }
  const TriangleSoup& soup = *scene.triangles;
  const size_t n = soup.triangle_count();
  if (soup.positions.size() != 3 * n || soup.normals.size() != 3 * n || soup.material_id.size() != n) {
    broken("soup arrays of unequal lengths");
  }
  if (!soup.uvs.empty() && soup.uvs.size() != 3 * n) broken("uvs neither empty nor one per corner");
  for (size_t i = 0; i < 3 * n; ++i) {
    if (!finite(soup.positions[i])) broken("position " + std::to_string(i) + " not finite");
    if (!finite(soup.normals[i])) broken("normal " + std::to_string(i) + " not finite");
    if (!soup.uvs.empty() && !finite(soup.uvs[i])) broken("uv " + std::to_string(i) + " not finite");
  }
  for (size_t t = 0; t < n; ++t) {
    if (soup.material_id[t] >= scene.materials.size())
      broken("triangle " + std::to_string(t) + ": material id out of range");
    if (soup.object_id[t] >= scene.objects.size()) broken("triangle " + std::to_string(t) + ": object id out of range");
  }
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const SceneObject& obj = scene.objects[o];
    if (obj.material >= scene.materials.size()) broken(obj.path + ": material out of range");
    if (uint64_t{obj.first_triangle} + obj.triangle_count > n) broken(obj.path + ": triangle range past the soup");
    for (uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t) {
      if (soup.object_id[t] != o) broken(obj.path + ": triangle " + std::to_string(t) + " names another object");
    }
    if (obj.triangle_count == 0) {
      bool warned = false;
      for (const std::string& w : scene.warnings) warned = warned || w.find(obj.path) != std::string::npos;
      if (!warned) broken(obj.path + ": no triangles and no warning");
    }
  }
  for (const std::string& w : scene.warnings) check_message(w, scene.file);
  // THE RADIANCE BOUND: an accepted scene cannot overflow a float; a small one is traced at
  // 4 x 3 pixels to see it (the tracer shades as every method does).
  const double bound = radiance_bound(scene, scene.render.max_depth);
  if (!(bound <= MAX_RADIANCE)) broken("accepted a scene whose pixels may reach " + std::to_string(bound));
  if (n <= 2000) {
    SceneData small = scene;
    small.camera.width = 4;
    small.camera.height = 3;
    RaytraceOptions o;
    o.threads = 1;
    o.samples_per_pixel = 1;
    const Image image = render_raytrace(small, o);
    for (const float v : image.data) {
      if (!std::isfinite(v) || v < 0.0f || v > MAX_RADIANCE) broken("a pixel of " + std::to_string(v));
    }
  }
  if (verbose()) {
    std::fprintf(stderr, "loaded: %zu objects, %zu triangles, %zu materials, %zu warnings\n", scene.objects.size(), n,
                 scene.materials.size(), scene.warnings.size());
  }
}

void check_message(const std::string& message, const std::string& place) {
  if (message.size() > MAX_MESSAGE_BYTES) broken("message of " + std::to_string(message.size()) + " bytes");
  if (message.find('\n') != std::string::npos || message.find('\r') != std::string::npos) {
    broken("message of more than one line: " + message);
  }
  if (message.rfind(place + ":", 0) != 0) broken("message without its place " + place + ": " + message);
  if (verbose()) std::fprintf(stderr, "message: %s\n", message.c_str());
}

bool expect_input_error_or_success(const std::function<void()>& load, const std::string& place) {
  try {
    load();
    return true;
  } catch (const InputError& e) {
    check_message(e.what(), place);
  } catch (const std::exception& e) {
    broken(std::string("not an InputError (") + typeid(e).name() + "): " + e.what());
  }
  return false;
}

namespace {

struct Scratch {
  std::string dir;
  Scratch() {
    const char* base = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
    std::string pattern = std::string(base) + "/abcube_fuzz.XXXXXX";
    if (!mkdtemp(pattern.data())) broken("cannot make a scratch folder under " + std::string(base));
    dir = pattern;
  }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

}  // namespace

const std::string& scratch_dir() {
  static const Scratch scratch;
  return scratch.dir;
}

void write_file(const std::string& path, const uint8_t* bytes, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes), static_cast<std::streamsize>(size));
  if (!out.flush()) broken("cannot write " + path);
}

}  // namespace abcube::fuzz
