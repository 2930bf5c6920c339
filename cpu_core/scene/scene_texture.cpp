// Texture files of a scene (a material's "texture", an MTL map_Kd, a glTF's embedded
// images): resolved and confined to LoadLimits::root as they are named, decoded once the
// objects are read (scene/texture.hpp).
#include <filesystem>
#include <map>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "scene/scene_load_state.hpp"
#include "scene/texture.hpp"

namespace abcube::detail {

namespace {

constexpr const char* EMBEDDED_PREFIX = "#embedded/";

}  // namespace

std::string texture_file(LoadState& st, const std::string& path, const std::string& where, const std::string& file,
                         const std::string& base_dir) {
  namespace fs = std::filesystem;
  if (file.empty()) fail(st.src, path, where + "must name an image file, got \"\"");
  const fs::path p(file);
  const std::string resolved =
      (p.is_absolute() ? p : fs::path(base_dir.empty() ? "." : base_dir) / p).lexically_normal().string();
  if (!st.root.empty() && !inside_root(st.root, resolved)) {
    fail(st.src, path, where + quote_path(file) + " resolves outside --root " + st.root);
  }
  const std::string problem = input_file_problem(resolved, MAX_TEXTURE_FILE_BYTES);
  if (!problem.empty()) fail(st.src, path, where + "cannot read texture " + quote_path(resolved) + ": " + problem);
  st.texture_place.emplace(resolved, std::make_pair(path, where));
  return resolved;
}

void load_textures(LoadState& st) {
  SceneData& scene = st.scene;
  std::map<std::string, int> image_of;  // Material::texture -> index into images
  std::vector<TextureImage> images;
  std::vector<int> material_image(scene.materials.size(), -1);
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const std::string& texture = scene.materials[m].texture;
    if (texture.empty()) continue;
    const auto known = image_of.find(texture);
    if (known != image_of.end()) {
      material_image[m] = known->second;
      continue;
    }
    TextureImage image;
    std::string why;
    if (texture.rfind(EMBEDDED_PREFIX, 0) == 0) {
      const std::string index = texture.substr(std::char_traits<char>::length(EMBEDDED_PREFIX));
      size_t i = scene.embedded_images.size();
      if (!index.empty() && index.find_first_not_of("0123456789") == std::string::npos && index.size() < 10) {
        i = std::stoul(index);
      }
      const std::string place = "materials[" + std::to_string(m) + "] " + quote(scene.materials[m].name) + ".texture";
      if (i >= scene.embedded_images.size() || !scene.embedded_images[i].bytes) {
        fail(st.src, place, "names " + quote(texture) + ", which is no embedded image");
      }
      const EmbeddedImage& e = scene.embedded_images[i];
      if (!decode_texture(e.bytes->data(), e.bytes->size(), e.name, e.mime_type, &image, &why)) {
        fail(st.src, place, "cannot decode texture " + quote(e.name) + ": " + why);
      }
    } else {
      const auto at = st.texture_place.find(texture);
      const std::string path = at == st.texture_place.end() ? "materials" : at->second.first;
      const std::string where = at == st.texture_place.end() ? "" : at->second.second;
      std::string bytes;
      try {
        bytes = read_input_file(texture, MAX_TEXTURE_FILE_BYTES, "texture");
      } catch (const InputError& e) {
        fail(st.src, path, where + e.what());
      }
      if (!decode_texture(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), texture, "", &image,
                          &why)) {
        fail(st.src, path, where + "cannot decode texture " + quote_path(texture) + ": " + why);
      }
    }
    material_image[m] = static_cast<int>(images.size());
    image_of.emplace(texture, material_image[m]);
    images.push_back(std::move(image));
  }
  if (!images.empty())
    scene.textures = std::make_shared<const TextureSet>(std::move(images), std::move(material_image));
}

}  // namespace abcube::detail
