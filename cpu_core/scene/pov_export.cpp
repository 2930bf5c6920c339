#include "scene/pov_export.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "base/error.hpp"

namespace abcube {

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// A float written with the digits that round-trip it.
std::string num_f(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
  return buf;
}

// A point or vector in POV-Ray's left-handed frame: z mirrored.
std::string vec(const glm::dvec3& v) { return "<" + num(v.x) + ", " + num(v.y) + ", " + num(-v.z) + ">"; }
std::string vec_f(const glm::vec3& v) { return "<" + num_f(v.x) + ", " + num_f(v.y) + ", " + num_f(-v.z) + ">"; }
std::string rgb(const glm::dvec3& c) { return "<" + num(c.r) + ", " + num(c.g) + ", " + num(c.b) + ">"; }

// A comment-safe copy of a user string (no line breaks).
std::string comment_safe(const std::string& s) {
  std::string out;
  for (char c : s) out += (c == '\n' || c == '\r') ? ' ' : c;
  return out;
}

void write_header(std::ostringstream& os, const SceneData& scene) {
  os << "// Exported by abcube from " << comment_safe(scene.file.empty() ? "(memory)" : scene.file) << "\n"
     << "// z is mirrored: POV-Ray is left-handed (abcube docs/design/pov-export.md).\n"
     << "#version 3.7;\n"
     << "global_settings {\n"
     << "  assumed_gamma 1.0\n"
     << "  max_trace_level " << scene.render.max_depth + 1 << "\n"
     << "  adc_bailout 0\n"
     << "  ambient_light rgb " << rgb(scene.ambient) << "\n"
     << "}\n"
     << "background { rgb " << rgb(scene.background) << " }\n";
}

void write_camera(std::ostringstream& os, const Camera& c) {
  const double aspect = static_cast<double>(c.width) / c.height;
  const double direction = 0.5 / std::tan(glm::radians(c.fov_y_deg) * 0.5);
  os << "camera {\n"
     << "  perspective\n"
     << "  location " << vec(c.position) << "\n"
     << "  direction <0, 0, " << num(direction) << ">\n"
     << "  right x*" << num(aspect) << "\n"
     << "  up y\n"
     << "  sky " << vec(c.up) << "\n"
     << "  look_at " << vec(c.look_at) << "\n"
     << "}\n";
}

void write_lights(std::ostringstream& os, const SceneData& scene) {
  for (const PointLight& l : scene.lights) {
    os << "light_source { " << vec(l.position) << " color rgb " << rgb(l.color) << (l.cast_shadows ? "" : " shadowless")
       << " }\n";
  }
}

void write_material(std::ostringstream& os, const Material& m, size_t index) {
  const double transmit = m.transmit > 0.0 ? m.transmit : 1.0 - m.opacity;
  os << "// material " << index << ": " << comment_safe(m.name) << "\n"
     << "#declare ABCUBE_M" << index << " = material {\n"
     << "  texture {\n"
     << "    pigment { rgbt <" << num(m.color.r) << ", " << num(m.color.g) << ", " << num(m.color.b) << ", "
     << num(transmit) << "> }\n"
     << "    finish { ambient " << num(m.ambient) << " diffuse " << num(m.diffuse);
  if (m.specular > 0.0) os << " phong " << num(m.specular) << " phong_size " << num(m.shininess);
  os << " specular 0 reflection { " << num(m.reflect) << " } }\n"
     << "  }\n";
  if (m.transmit > 0.0) os << "  interior { ior " << num(m.ior) << " }\n";
  os << "}\n";
}

// One mesh2 holding the given triangles of the soup (vertices and normals unshared).
void write_mesh(std::ostringstream& os, const TriangleSoup& soup, const std::vector<uint32_t>& tris,
                uint32_t material) {
  const size_t nv = 3 * tris.size();
  os << "mesh2 {\n  vertex_vectors { " << nv;
  for (uint32_t t : tris) {
    for (int k = 0; k < 3; ++k) os << ",\n    " << vec_f(soup.positions[3 * static_cast<size_t>(t) + k]);
  }
  os << "\n  }\n  normal_vectors { " << nv;
  for (uint32_t t : tris) {
    for (int k = 0; k < 3; ++k) os << ",\n    " << vec_f(soup.normals[3 * static_cast<size_t>(t) + k]);
  }
  os << "\n  }\n  face_indices { " << tris.size();
  for (size_t i = 0; i < tris.size(); ++i) {
    os << ",\n    <" << 3 * i << ", " << 3 * i + 1 << ", " << 3 * i + 2 << ">";
  }
  os << "\n  }\n  material { ABCUBE_M" << material << " }\n}\n";
}

}  // namespace

std::string export_pov(const SceneData& scene) {
  const TriangleSoup& soup = *scene.triangles;
  ABCUBE_CHECK(soup.positions.size() == 3 * soup.triangle_count() && soup.normals.size() == soup.positions.size(),
               "triangle soup with 3 positions and 3 normals per triangle");
  std::ostringstream os;
  write_header(os, scene);
  write_camera(os, scene.camera);
  write_lights(os, scene);
  for (size_t i = 0; i < scene.materials.size(); ++i) write_material(os, scene.materials[i], i);
  // One mesh2 per (object, material), ordered by object then material.
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> groups;
  for (uint32_t t = 0; t < soup.triangle_count(); ++t) {
    ABCUBE_CHECK(soup.material_id[t] < scene.materials.size(), "material id out of range");
    groups[{soup.object_id[t], soup.material_id[t]}].push_back(t);
  }
  for (const auto& [key, tris] : groups) {
    os << "// object " << key.first;
    if (key.first < scene.objects.size()) os << " (" << comment_safe(scene.objects[key.first].path) << ")";
    os << "\n";
    write_mesh(os, soup, tris, key.second);
  }
  return os.str();
}

}  // namespace abcube
