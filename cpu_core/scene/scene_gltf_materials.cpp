// glTF materials, textures, cameras and lights (scene_gltf_reader.hpp).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/constants.hpp"
#include "base/error.hpp"
#include "base/input_file.hpp"
#include "scene/scene_gltf_reader.hpp"

namespace abcube::detail::gltf {

// ---- materials ----
const tg::Material* GltfReader::material_at(int index) const {
  return index >= 0 && static_cast<size_t>(index) < model_.materials.size()
             ? &model_.materials[static_cast<size_t>(index)]
             : nullptr;
}

int GltfReader::texcoord_set(int material) const {
  const tg::Material* m = material_at(material);
  return m && m->pbrMetallicRoughness.baseColorTexture.index >= 0 ? m->pbrMetallicRoughness.baseColorTexture.texCoord
                                                                  : 0;
}

int GltfReader::material_of(int index, const std::string& at) {
  if (!use_materials_) return -1;  // the object's own
  if (index < 0) return static_cast<int>(default_material(st_));
  if (static_cast<size_t>(index) >= model_.materials.size()) {
    bad(at,
        "index " + std::to_string(index) + " out of range (" + std::to_string(model_.materials.size()) + " materials)");
  }
  const std::string key = resolved_ + '\n' + std::to_string(index);
  auto it = st_.mtl_materials.find(key);
  if (it == st_.mtl_materials.end())
    it = st_.mtl_materials.emplace(key, add_material(st_, convert_material(index))).first;
  return static_cast<int>(it->second);
}

double GltfReader::extension_number(const tg::ExtensionMap& ext, const char* name, const char* key, double fallback,
                                    bool* present) {
  const auto it = ext.find(name);
  if (it == ext.end()) return fallback;
  if (present) *present = true;
  if (!it->second.Has(key) || !it->second.Get(key).IsNumber()) return fallback;
  return it->second.Get(key).GetNumberAsDouble();
}

Material GltfReader::convert_material(int index) {
  const tg::Material& g = model_.materials[static_cast<size_t>(index)];
  const std::string at = index_path("materials", static_cast<size_t>(index));
  Material m;
  m.name = file_ + ":" + (g.name.empty() ? at : g.name);
  const std::vector<double>& base = g.pbrMetallicRoughness.baseColorFactor;
  if (base.size() != 4) bad(at + ".pbrMetallicRoughness.baseColorFactor", "must have 4 numbers");
  for (int k = 0; k < 4; ++k) {
    if (!(base[static_cast<size_t>(k)] >= 0 && base[static_cast<size_t>(k)] <= 1)) {
      bad(at + ".pbrMetallicRoughness.baseColorFactor", "must be 4 numbers in [0, 1]");
    }
  }
  m.color = glm::dvec3(base[0], base[1], base[2]);
  const auto unit = [&](double x, const std::string& key) {
    if (!(x >= 0 && x <= 1)) bad(member_path(at, key.c_str()), "must be in [0, 1], got " + format_number(x));
    return x;
  };
  const double metallic = unit(g.pbrMetallicRoughness.metallicFactor, "pbrMetallicRoughness.metallicFactor");
  const double rough = unit(g.pbrMetallicRoughness.roughnessFactor, "pbrMetallicRoughness.roughnessFactor");
  const double transmission =
      unit(extension_number(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0),
           "extensions.KHR_materials_transmission.transmissionFactor");
  bool has_ior = false;
  const double ior = extension_number(g.extensions, "KHR_materials_ior", "ior", 1.5, &has_ior);
  if (!std::isfinite(ior) || (ior < 1 && ior != 0)) {
    bad(at + ".extensions.KHR_materials_ior.ior", "must be >= 1 (or 0), got " + format_number(ior));
  }
  m.transmit = transmission * (1.0 - metallic);
  m.reflect = std::min(metallic * (1.0 - rough), 1.0 - m.transmit);
  m.diffuse = m.ambient = 1.0 - m.reflect - m.transmit;
  m.ior = (m.transmit > 0 || has_ior) && ior >= 1 ? ior : (m.transmit > 0 ? 1.5 : 1.0);
  m.specular = 0.5 * (1.0 - rough);
  m.shininess = std::clamp(2.0 / std::max(std::pow(rough, 4.0), 1e-6) - 2.0, 1.0, 1000.0);
  const std::string mode = g.alphaMode.empty() ? "OPAQUE" : g.alphaMode;
  if (mode == "BLEND") {
    m.opacity = base[3];
  } else if (mode == "MASK") {
    m.opacity = base[3] >= g.alphaCutoff ? 1.0 : 0.0;
    if (g.pbrMetallicRoughness.baseColorTexture.index >= 0)
      note("MASK by the texture's alpha (the factor's alpha decides)");
  } else if (mode != "OPAQUE") {
    bad(member_path(at, "alphaMode"), "must be OPAQUE, MASK or BLEND, got " + quote(mode));
  }
  for (size_t k = 0; k < g.emissiveFactor.size(); ++k) {
    if (g.emissiveFactor[k] > 0) note("emission (emissiveFactor)");
  }
  if (g.emissiveTexture.index >= 0) note("emission (emissiveTexture)");
  for (const auto& e : g.extensions) {
    if (e.first == "KHR_materials_transmission" || e.first == "KHR_materials_ior") continue;
    note(e.first == "KHR_materials_pbrSpecularGlossiness" ? e.first + " (its metallic-roughness values are used)"
                                                          : e.first);
  }
  const tg::TextureInfo& tex = g.pbrMetallicRoughness.baseColorTexture;
  if (tex.index >= 0) {
    if (tex.extensions.count("KHR_texture_transform")) note("KHR_texture_transform");
    m.texture = texture_name(tex.index, at + ".pbrMetallicRoughness.baseColorTexture.index");
  }
  return m;
}

// Material::texture for textures[index]: the image file, or "#embedded/I".
std::string GltfReader::texture_name(int index, const std::string& at) {
  if (static_cast<size_t>(index) >= model_.textures.size()) {
    bad(at,
        "texture " + std::to_string(index) + " out of range (" + std::to_string(model_.textures.size()) + " textures)");
  }
  const int source = model_.textures[static_cast<size_t>(index)].source;
  if (source < 0) return "";  // an image only an extension names (KHR_texture_basisu, EXT_texture_webp)
  if (static_cast<size_t>(source) >= model_.images.size()) {
    bad(index_path("textures", static_cast<size_t>(index)) + ".source",
        "image " + std::to_string(source) + " out of range (" + std::to_string(model_.images.size()) + " images)");
  }
  const std::string iat = index_path("images", static_cast<size_t>(source));
  const auto known = image_texture_.find(source);
  if (known != image_texture_.end()) return known->second;
  const tg::Image& image = model_.images[static_cast<size_t>(source)];
  std::string name;
  if (image.bufferView >= 0) {
    if (static_cast<size_t>(image.bufferView) >= model_.bufferViews.size()) bad(iat, "bufferView out of range");
    const tg::BufferView& bv = model_.bufferViews[static_cast<size_t>(image.bufferView)];
    if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= model_.buffers.size() ||
        bv.byteOffset > model_.buffers[static_cast<size_t>(bv.buffer)].data.size() ||
        bv.byteLength > model_.buffers[static_cast<size_t>(bv.buffer)].data.size() - bv.byteOffset) {
      bad(iat, "its bufferView runs past the end of its buffer");
    }
    const unsigned char* b = model_.buffers[static_cast<size_t>(bv.buffer)].data.data() + bv.byteOffset;
    name = embed(iat, image.mimeType, std::vector<unsigned char>(b, b + bv.byteLength));
  } else if (!image.image.empty()) {
    name = embed(iat, image.mimeType, image.image);  // a data: URI
  } else if (!image.uri.empty() && !missing_images_.count(iat)) {
    name = texture_file(st_, path_, quote_path(file_) + ": " + iat + ".uri ", url_decode(image.uri), folder());
  }
  image_texture_[source] = name;
  return name;
}

std::string GltfReader::embed(const std::string& at, const std::string& mime, std::vector<unsigned char> bytes) {
  EmbeddedImage e;
  e.name = file_ + ": " + at;
  e.mime_type = mime;
  e.bytes = std::make_shared<const std::vector<unsigned char>>(std::move(bytes));
  st_.scene.embedded_images.push_back(std::move(e));
  return "#embedded/" + std::to_string(st_.scene.embedded_images.size() - 1);
}

// ---- cameras and lights ----
void GltfReader::add_camera(int index, const std::string& at, const glm::dmat4& world) {
  if (static_cast<size_t>(index) >= model_.cameras.size()) {
    bad(member_path(at, "camera"),
        "index " + std::to_string(index) + " out of range (" + std::to_string(model_.cameras.size()) + " cameras)");
  }
  const tg::Camera& c = model_.cameras[static_cast<size_t>(index)];
  if (c.type != "perspective") {
    note("orthographic cameras");
    return;
  }
  if (extras_->has_camera) return;  // the first one found
  const double yfov_deg = c.perspective.yfov * 180.0 / PI;
  if (!(yfov_deg > 0 && yfov_deg < 180)) {
    bad(index_path("cameras", static_cast<size_t>(index)) + ".perspective.yfov",
        "must be in (0, pi), got " + format_number(c.perspective.yfov));
  }
  const glm::dvec3 eye(world * glm::dvec4(0, 0, 0, 1));
  const glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0, 0, -1);
  const glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0, 1, 0);
  if (!(glm::length(forward) > 0) || !(glm::length(glm::cross(forward, up)) > 0)) {
    bad(at, "its transform flattens the camera");
  }
  extras_->has_camera = true;
  extras_->camera_position = eye;
  extras_->camera_look_at = eye + glm::normalize(forward);
  extras_->camera_up = up;
  extras_->camera_fov_y_deg = yfov_deg;
}

void GltfReader::add_light(const tg::Value& v, const std::string& at, const glm::dmat4& world) {
  const std::string lat = at + ".extensions.KHR_lights_punctual.light";
  if (!v.IsInt() || v.GetNumberAsInt() < 0 || static_cast<size_t>(v.GetNumberAsInt()) >= model_.lights.size()) {
    bad(lat, "must index the file's KHR_lights_punctual lights (" + std::to_string(model_.lights.size()) + ")");
  }
  const tg::Light& l = model_.lights[static_cast<size_t>(v.GetNumberAsInt())];
  if (l.type != "point") {
    note("KHR_lights_punctual " + l.type + " lights");
    return;
  }
  glm::dvec3 color(1.0);
  if (l.color.size() == 3) color = glm::dvec3(l.color[0], l.color[1], l.color[2]);
  const glm::dvec3 c = color * l.intensity;
  if (!(c.x >= 0 && c.y >= 0 && c.z >= 0 && std::isfinite(c.x + c.y + c.z))) {
    bad(lat, "color times intensity must be finite and >= 0");
  }
  PointLight p;
  p.position = glm::dvec3(world * glm::dvec4(0, 0, 0, 1));
  p.color = c;
  lights_.push_back(p);
}

// Our lights do not fall off with distance: a glTF point light of I candela becomes the
// colour I / d^2 (1 cd at 1 m gives 1), d its distance from the centre of the file's
// triangles (the inverse square evaluated once, where the model is).
void GltfReader::finish_lights() {
  Bounds b;
  for (const uint32_t v : out_.position_index) {  // the vertices of triangles only
    const glm::dvec3& p = out_.positions[v];
    if (std::isfinite(p.x + p.y + p.z)) b.extend(p);
  }
  const glm::dvec3 centre = b.empty() ? glm::dvec3(0.0) : 0.5 * (b.lo + b.hi);
  const double floor = b.empty() ? 1.0 : std::max(1e-3 * glm::length(b.hi - b.lo), 1e-12);
  for (PointLight l : lights_) {
    const double d = std::max(glm::length(l.position - centre), floor);
    l.color /= d * d;
    extras_->lights.push_back(l);
  }
}

}  // namespace abcube::detail::gltf
